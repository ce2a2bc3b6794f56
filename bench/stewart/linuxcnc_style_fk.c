/* Forward kinematics of the Stewart-Gough platform as LinuxCNC's hexapod kinematics is
 * described to work (written from that description, not from its code): Newton's method on
 * the six leg lengths, at most 120 iterations, converged when every leg-length error is below
 * 1e-9; each iteration builds the 6x6 Jacobian of the leg lengths with respect to the
 * platform's translation and a small rotation, inverts it by Gauss-Jordan elimination, and
 * adds the rotation part of the step to the roll/pitch/yaw angles directly, without the
 * mapping from angular velocity to angle rates (so it converges inexactly, or slowly, at
 * large tilt). */
#include <math.h>

#include "linuxcnc_style_fk.h"

#define LEG_TOLERANCE 1e-9
#define MAX_ITERATIONS 120

/* Invert the 6x6 matrix a (destroyed) into inv by Gauss-Jordan with partial pivoting;
 * returns 0, or -1 when a pivot is zero. */
static int gauss_jordan_inverse(double a[6][6], double inv[6][6])
{
    int i, j, k;
    for (i = 0; i < 6; ++i)
        for (j = 0; j < 6; ++j)
            inv[i][j] = i == j;
    for (k = 0; k < 6; ++k) {
        int best = k;
        double pivot;
        for (i = k + 1; i < 6; ++i)
            if (fabs(a[i][k]) > fabs(a[best][k]))
                best = i;
        if (a[best][k] == 0)
            return -1;
        for (j = 0; j < 6; ++j) {
            double t = a[k][j]; a[k][j] = a[best][j]; a[best][j] = t;
            t = inv[k][j]; inv[k][j] = inv[best][j]; inv[best][j] = t;
        }
        pivot = a[k][k];
        for (j = 0; j < 6; ++j) {
            a[k][j] /= pivot;
            inv[k][j] /= pivot;
        }
        for (i = 0; i < 6; ++i) {
            double f;
            if (i == k)
                continue;
            f = a[i][k];
            for (j = 0; j < 6; ++j) {
                a[i][j] -= f * a[k][j];
                inv[i][j] -= f * inv[k][j];
            }
        }
    }
    return 0;
}

int linuxcnc_style_fk(void *context, const double legs[6], double pose[6], int *iterations)
{
    const stewart_geometry *g = (const stewart_geometry *)context;
    int iteration;
    for (iteration = 0; iteration < MAX_ITERATIONS; ++iteration) {
        double R[3][3], J[6][6], inv[6][6], error[6], worst = 0;
        int i, r;
        stewart_rotation(pose[3], pose[4], pose[5], R);
        for (i = 0; i < 6; ++i) {
            double rp[3], leg[3], length = 0;
            for (r = 0; r < 3; ++r) {
                rp[r] = R[r][0] * g->platform[i][0] + R[r][1] * g->platform[i][1]
                      + R[r][2] * g->platform[i][2];
                leg[r] = pose[r] + rp[r] - g->base[i][r];
                length += leg[r] * leg[r];
            }
            length = sqrt(length);
            error[i] = length - legs[i];
            worst = fabs(error[i]) > worst ? fabs(error[i]) : worst;
            for (r = 0; r < 3; ++r)
                leg[r] /= length; /* unit leg direction n */
            J[i][0] = leg[0]; J[i][1] = leg[1]; J[i][2] = leg[2];
            J[i][3] = rp[1] * leg[2] - rp[2] * leg[1]; /* (R P_i) x n: small rotation */
            J[i][4] = rp[2] * leg[0] - rp[0] * leg[2];
            J[i][5] = rp[0] * leg[1] - rp[1] * leg[0];
        }
        if (worst < LEG_TOLERANCE) {
            *iterations = iteration;
            return 0;
        }
        if (gauss_jordan_inverse(J, inv) != 0) {
            *iterations = iteration;
            return -1;
        }
        for (r = 0; r < 6; ++r) {
            double step = 0;
            for (i = 0; i < 6; ++i)
                step += inv[r][i] * error[i];
            pose[r] -= step; /* angles updated as if they were the small rotation */
        }
    }
    *iterations = MAX_ITERATIONS;
    return 1;
}

/* Stewart-Gough platform for the forward-kinematics benchmark: geometry, pose trajectory and
 * the closed-form inverse kinematics (leg lengths of a pose), shared by every solver timed.
 *
 * A pose is {x, y, z, a, b, c}: the platform frame's origin in the base frame and its
 * orientation R = Rz(c) Ry(b) Rx(a) (roll a about x, then pitch b about y, then yaw c about z).
 * Leg i joins base point B_i (base frame) to platform point P_i (platform frame):
 *     L_i = | x + R P_i - B_i |.
 *
 * A forward-kinematics solver plugs into fk_bench.c through this signature:
 *     int solve(void *context, const double legs[6], double pose[6], int *iterations);
 * pose holds the guess on entry (the previous solution) and the solution on return; the
 * return value is 0 on convergence, non-zero otherwise; *iterations receives the count.
 */
#ifndef STEWART_H
#define STEWART_H

typedef int (*fk_solve_fn)(void *context, const double legs[6], double pose[6],
                           int *iterations);

typedef struct {
    double base[6][3];     /* B_i in the base frame */
    double platform[6][3]; /* P_i in the platform frame */
} stewart_geometry;

/* The usual 6-6 layout: joints in pairs on two circles, base radius 1, platform radius 0.6,
 * pairs 20 degrees apart on the base and 40 degrees apart on the platform. */
void stewart_default_geometry(stewart_geometry *g);

/* R = Rz(c) Ry(b) Rx(a), row-major. */
void stewart_rotation(double a, double b, double c, double R[3][3]);

/* Inverse kinematics in closed form: the six leg lengths of a pose. */
void stewart_legs(const stewart_geometry *g, const double pose[6], double legs[6]);

/* Pose k of n along a smooth closed path: a circle of radius 0.1 about the home height 1,
 * a heave of 0.05 and roll, pitch, yaw of amplitude `tilt` (radians). */
void stewart_trajectory(int k, int n, double tilt, double pose[6]);

#endif /* STEWART_H */

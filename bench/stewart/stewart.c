/* Geometry, rotation, inverse kinematics and trajectory of the benchmark's Stewart-Gough
 * platform (see stewart.h). */
#include <math.h>

#include "stewart.h"

/* The usual 6-6 layout: joints in pairs on two circles, base radius 1, platform radius 0.6,
 * pairs 20 degrees apart on the base and 40 degrees apart on the platform. */
void stewart_default_geometry(stewart_geometry *g)
{
    const double pi = 3.14159265358979323846;
    int i;
    for (i = 0; i < 6; ++i) {
        const int pair = i / 2, side = i % 2 ? 1 : -1;
        const double base_angle = pair * 2 * pi / 3 + side * 10 * pi / 180;
        const double top_angle = pair * 2 * pi / 3 + pi / 3 - side * 40 * pi / 180;
        g->base[i][0] = cos(base_angle);
        g->base[i][1] = sin(base_angle);
        g->base[i][2] = 0;
        g->platform[i][0] = 0.6 * cos(top_angle);
        g->platform[i][1] = 0.6 * sin(top_angle);
        g->platform[i][2] = 0;
    }
}

/* R = Rz(c) Ry(b) Rx(a), row-major. */
void stewart_rotation(double a, double b, double c, double R[3][3])
{
    const double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b), cc = cos(c), sc = sin(c);
    R[0][0] = cc * cb; R[0][1] = cc * sb * sa - sc * ca; R[0][2] = cc * sb * ca + sc * sa;
    R[1][0] = sc * cb; R[1][1] = sc * sb * sa + cc * ca; R[1][2] = sc * sb * ca - cc * sa;
    R[2][0] = -sb;     R[2][1] = cb * sa;                R[2][2] = cb * ca;
}

/* Inverse kinematics in closed form: the six leg lengths of a pose. */
void stewart_legs(const stewart_geometry *g, const double pose[6], double legs[6])
{
    double R[3][3];
    int i, r;
    stewart_rotation(pose[3], pose[4], pose[5], R);
    for (i = 0; i < 6; ++i) {
        double sum = 0;
        for (r = 0; r < 3; ++r) {
            const double v = pose[r] + R[r][0] * g->platform[i][0] + R[r][1] * g->platform[i][1]
                           + R[r][2] * g->platform[i][2] - g->base[i][r];
            sum += v * v;
        }
        legs[i] = sqrt(sum);
    }
}

/* Pose k of n along a smooth closed path: a circle of radius 0.1 about the home height 1,
 * a heave of 0.05 and roll, pitch, yaw of amplitude `tilt` (radians). */
void stewart_trajectory(int k, int n, double tilt, double pose[6])
{
    const double pi = 3.14159265358979323846;
    const double s = 2 * pi * k / n;
    pose[0] = 0.1 * cos(s);
    pose[1] = 0.1 * sin(s);
    pose[2] = 1.0 + 0.05 * sin(2 * s);
    pose[3] = tilt * sin(s);
    pose[4] = tilt * cos(s);
    pose[5] = 0.5 * tilt * sin(3 * s);
}

/* Timing harness of Stewart-Gough forward kinematics along a pose trajectory.
 *
 * For each tilt amplitude, the poses of stewart_trajectory are turned into leg lengths by the
 * closed-form inverse kinematics; every solver of the table in main then recovers the poses from the leg
 * lengths, each solve starting from the previous solution (as in a servo loop). Printed per
 * solver and tilt: microseconds per solve (best of the repeats, wall clock over the whole
 * trajectory), mean and largest iteration counts, the largest pose error (position and angle)
 * against the prescribed poses, the largest leg-length error of the returned poses, and the
 * solves that reported failure.
 *
 * Another solver is timed by adding a line to the solvers table of main: its function has the signature of
 * fk_solve_fn (stewart.h) and its context pointer is passed through unchanged.
 *
 * Usage: fk_bench [POSES [REPEATS [SOLVER]]]   (default 10000 poses, best of 5; SOLVER: only
 * the solvers whose name contains it, e.g. to count one solver's instructions)
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "linuxcnc_style_fk.h"
#ifdef FK_EXTRA_SOLVERS
/* Solvers compiled in by another script (symkin_fk.py): the header declares them and
 * defines FK_EXTRA_SOLVERS_TABLE, lines of the solvers table below. */
#include "extra_solvers.h"
#endif

typedef struct {
    const char *name;
    fk_solve_fn solve;
    void *context;
} fk_solver;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double angle_difference(double a, double b)
{
    const double pi = 3.14159265358979323846;
    return fabs(remainder(a - b, 2 * pi));
}

static void run(const fk_solver *solver, const stewart_geometry *g, int n, int repeats,
                double tilt)
{
    double *poses = malloc(sizeof(double) * 6 * n), *legs = malloc(sizeof(double) * 6 * n);
    double *found = malloc(sizeof(double) * 6 * n);
    int *iterations = malloc(sizeof(int) * n);
    double best = INFINITY, position_error = 0, angle_error = 0, leg_error = 0;
    long total_iterations = 0;
    int k, j, r, most = 0, failures = 0;
    for (k = 0; k < n; ++k) {
        stewart_trajectory(k, n, tilt, poses + 6 * k);
        stewart_legs(g, poses + 6 * k, legs + 6 * k);
    }
    for (r = 0; r < repeats; ++r) {
        double guess[6] = {0, 0, 1, 0, 0, 0}, started, elapsed;
        failures = 0;
        started = now_seconds();
        for (k = 0; k < n; ++k) {
            failures += solver->solve(solver->context, legs + 6 * k, guess, iterations + k) != 0;
            for (j = 0; j < 6; ++j)
                found[6 * k + j] = guess[j];
        }
        elapsed = now_seconds() - started;
        best = elapsed < best ? elapsed : best;
    }
    for (k = 0; k < n; ++k) {
        double check[6];
        stewart_legs(g, found + 6 * k, check);
        for (j = 0; j < 3; ++j)
            position_error = fmax(position_error, fabs(found[6 * k + j] - poses[6 * k + j]));
        for (j = 3; j < 6; ++j)
            angle_error = fmax(angle_error, angle_difference(found[6 * k + j], poses[6 * k + j]));
        for (j = 0; j < 6; ++j)
            leg_error = fmax(leg_error, fabs(check[j] - legs[6 * k + j]));
        total_iterations += iterations[k];
        most = iterations[k] > most ? iterations[k] : most;
    }
    printf("solver=%s tilt_rad=%.3f poses=%d us_per_solve=%.3f mean_iterations=%.2f "
           "max_iterations=%d max_position_error=%.3e max_angle_error=%.3e "
           "max_leg_error=%.3e failures=%d\n",
           solver->name, tilt, n, 1e6 * best / n, (double)total_iterations / n, most,
           position_error, angle_error, leg_error, failures);
    free(poses); free(legs); free(found); free(iterations);
}

int main(int argc, char **argv)
{
    static stewart_geometry geometry;
    const double tilts[] = {0.05, 0.5}; /* about 3 and 29 degrees */
    const int n = argc > 1 ? atoi(argv[1]) : 10000, repeats = argc > 2 ? atoi(argv[2]) : 5;
    fk_solver solvers[] = {
        {"linuxcnc_style", linuxcnc_style_fk, &geometry},
#ifdef FK_EXTRA_SOLVERS
        FK_EXTRA_SOLVERS_TABLE
#endif
    };
    size_t s, t;
    if (n < 1 || repeats < 1) {
        fprintf(stderr, "usage: fk_bench [POSES [REPEATS]] (positive integers)\n");
        return 2;
    }
    stewart_default_geometry(&geometry);
    for (t = 0; t < sizeof tilts / sizeof tilts[0]; ++t)
        for (s = 0; s < sizeof solvers / sizeof solvers[0]; ++s)
            if (argc <= 3 || strstr(solvers[s].name, argv[3]) != NULL)
                run(&solvers[s], &geometry, n, repeats, tilts[t]);
    return 0;
}

/* The baseline of bench/sweep.py: one C loop over the generated crank-slider solver, one
 * crank_slider_solve_grid call per parameter set from a fresh state, written into
 * caller-owned m x n x NQ arrays. This is what a hand-written sweep in C would do. */
#include <string.h>

#include "crank_slider_solver.h"

long bench_sweep(int m, const double p[], int n, const double t[], double q[], double dq[],
                 double ddq[], int status[])
{
    crank_slider_options options;
    crank_slider_state state;
    crank_slider_workspace work;
    crank_slider_report report;
    long solved = 0;
    int j;
    crank_slider_default_options(&options);
    for (j = 0; j < m; ++j) {
        size_t offset = (size_t)j * (size_t)n * CRANK_SLIDER_NQ;
        memcpy(state.q, crank_slider_q0, sizeof state.q);
        state.started = 0;
        solved += crank_slider_solve_grid(&options, p + (size_t)j * CRANK_SLIDER_NP, n, t, &state,
                                          q + offset, dq + offset, ddq + offset, &work,
                                          &report) == n;
        status[j] = report.status;
    }
    return solved;
}

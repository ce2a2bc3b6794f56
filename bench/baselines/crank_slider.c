/* A careful hand-written C solver for the textbook crank-slider (Examples 2.5-2.8).
 *
 * Phi (eq. a of Example 2.5), Phi_q (b), Phi_t (c) and Gamma (d, h, i) written out by hand for
 * a = 1, b = 5, c = 4, and the chapter's loop over the whole grid in one call: Taylor predictor
 * (2.76), Newton on ||Phi|| (tolerance 1e-10, at most 25 iterations), velocity (2.73) and
 * acceleration (2.74) sharing one factorization at the converged q.
 *
 * Linear algebra: dense 9 x 9 LU with partial pivoting, fixed size so the compiler can unroll;
 * compiled with -DSPARSE_LU, the same loop calls the generated straight-line sparse LU instead
 * (crank_slider_lu_factor / _solve on the 17 non-zeros in the pattern's row-major order).
 */
#include <math.h>
#include <string.h>
#ifdef SPARSE_LU
#include "crank_slider_sparse_lu.h"
#endif

#define N 9
#define TOLERANCE 1e-10
#define MAX_ITERATIONS 25

static const double A = 1.0, B = 5.0, C = 4.0;
static const double HALF_PI = 1.57079632679489661923;

static void phi(const double q[N], double t, double f[N])
{
    f[0] = -q[0];
    f[1] = -q[1];
    f[2] = q[0] + A * cos(q[2]) - q[3];
    f[3] = q[1] + A * sin(q[2]) - q[4];
    f[4] = q[3] + B * cos(q[5]) - q[6];
    f[5] = q[4] + B * sin(q[5]) - q[7];
    f[6] = q[8];
    f[7] = C - q[7];
    f[8] = q[2] - t * t - HALF_PI;
}

/* The 17 structural non-zeros in row-major order. */
static void jacobian_nz(const double q[N], double nz[17])
{
    double s1 = sin(q[2]), c1 = cos(q[2]), s2 = sin(q[5]), c2 = cos(q[5]);
    nz[0] = -1;        /* (0,0) */
    nz[1] = -1;        /* (1,1) */
    nz[2] = 1;         /* (2,0) */
    nz[3] = -A * s1;   /* (2,2) */
    nz[4] = -1;        /* (2,3) */
    nz[5] = 1;         /* (3,1) */
    nz[6] = A * c1;    /* (3,2) */
    nz[7] = -1;        /* (3,4) */
    nz[8] = 1;         /* (4,3) */
    nz[9] = -B * s2;   /* (4,5) */
    nz[10] = -1;       /* (4,6) */
    nz[11] = 1;        /* (5,4) */
    nz[12] = B * c2;   /* (5,5) */
    nz[13] = -1;       /* (5,7) */
    nz[14] = 1;        /* (6,8) */
    nz[15] = -1;       /* (7,7) */
    nz[16] = 1;        /* (8,2) */
}

static void gamma_rhs(const double q[N], const double dq[N], double g[N])
{
    double w1 = dq[2] * dq[2], w2 = dq[5] * dq[5];
    memset(g, 0, N * sizeof g[0]);
    g[2] = A * cos(q[2]) * w1;
    g[3] = A * sin(q[2]) * w1;
    g[4] = B * cos(q[5]) * w2;
    g[5] = B * sin(q[5]) * w2;
    g[8] = 2;
}

#ifndef SPARSE_LU
typedef struct { double a[N][N]; int perm[N]; } dense_lu;

static void scatter(const double nz[17], double a[N][N])
{
    static const int row[17] = {0, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5, 6, 7, 8};
    static const int col[17] = {0, 1, 0, 2, 3, 1, 2, 4, 3, 5, 6, 4, 5, 7, 8, 7, 2};
    int e;
    memset(a, 0, N * N * sizeof a[0][0]);
    for (e = 0; e < 17; ++e) a[row[e]][col[e]] = nz[e];
}

/* 0 on success, k + 1 when column k has no non-zero pivot. */
static int lu_factor(const double nz[17], dense_lu *lu)
{
    int i, j, k;
    scatter(nz, lu->a);
    for (k = 0; k < N; ++k) {
        int p = k;
        double best = fabs(lu->a[k][k]);
        for (i = k + 1; i < N; ++i) {
            if (fabs(lu->a[i][k]) > best) { best = fabs(lu->a[i][k]); p = i; }
        }
        if (best == 0.0) return k + 1;
        lu->perm[k] = p;
        if (p != k) {
            for (j = 0; j < N; ++j) {
                double tmp = lu->a[k][j]; lu->a[k][j] = lu->a[p][j]; lu->a[p][j] = tmp;
            }
        }
        for (i = k + 1; i < N; ++i) {
            double m = lu->a[i][k] / lu->a[k][k];
            lu->a[i][k] = m;
            if (m != 0.0) {
                for (j = k + 1; j < N; ++j) lu->a[i][j] -= m * lu->a[k][j];
            }
        }
    }
    return 0;
}

static void lu_solve(const dense_lu *lu, double b[N])
{
    int i, j;
    for (i = 0; i < N; ++i) {
        int p = lu->perm[i];
        double tmp = b[i]; b[i] = b[p]; b[p] = tmp;
    }
    for (i = 1; i < N; ++i) {
        double s = b[i];
        for (j = 0; j < i; ++j) s -= lu->a[i][j] * b[j];
        b[i] = s;
    }
    for (i = N - 1; i >= 0; --i) {
        double s = b[i];
        for (j = i + 1; j < N; ++j) s -= lu->a[i][j] * b[j];
        b[i] = s / lu->a[i][i];
    }
}
#define LU_TYPE dense_lu
#define LU_FACTOR lu_factor
#define LU_SOLVE lu_solve
#define LU_FALLBACKS(lu) 0UL
#else
#define LU_TYPE crank_slider_lu
#define LU_FACTOR crank_slider_lu_factor
#define LU_SOLVE crank_slider_lu_solve
#define LU_FALLBACKS(lu) ((lu).fallbacks)
#endif

/* Solve the grid t = k dt, k = 0..steps, from q0 = 0. Q, DQ, D2Q: (steps + 1) x 9, row-major.
 * Returns 0, or k + 1 when step k fails (no convergence or singular Phi_q). */
long cs_solve_grid(long steps, double dt, double *Q, double *DQ, double *D2Q,
                   long *newton_iterations, unsigned long *fallbacks)
{
    double q[N] = {0}, dq[N] = {0}, d2q[N] = {0}, f[N], nz[17];
    LU_TYPE lu;
    long k, iterations = 0;
    int i, it;
#ifdef SPARSE_LU
    crank_slider_lu_init(&lu);
#endif
    for (k = 0; k <= steps; ++k) {
        double t = (double)k * dt, h = k == 0 ? 0.0 : dt;
        for (i = 0; i < N; ++i) q[i] += dq[i] * h + 0.5 * d2q[i] * h * h;
        for (it = 0; ; ++it) {
            double norm2 = 0.0;
            phi(q, t, f);
            for (i = 0; i < N; ++i) norm2 += f[i] * f[i];
            if (norm2 <= TOLERANCE * TOLERANCE) break;
            if (it == MAX_ITERATIONS) return k + 1;
            jacobian_nz(q, nz);
            if (LU_FACTOR(nz, &lu) != 0) return k + 1;
            LU_SOLVE(&lu, f);
            for (i = 0; i < N; ++i) q[i] -= f[i];
        }
        iterations += it;
        jacobian_nz(q, nz);
        if (LU_FACTOR(nz, &lu) != 0) return k + 1;
        memset(dq, 0, sizeof dq);
        dq[8] = 2.0 * t;          /* -Phi_t: only the driver row depends on t */
        LU_SOLVE(&lu, dq);
        gamma_rhs(q, dq, d2q);
        LU_SOLVE(&lu, d2q);
        memcpy(Q + k * N, q, sizeof q);
        memcpy(DQ + k * N, dq, sizeof dq);
        memcpy(D2Q + k * N, d2q, sizeof d2q);
    }
    *newton_iterations = iterations;
    *fallbacks = LU_FALLBACKS(lu);
    return 0;
}

/*
 * Private to the hand-written solvers of src/csrc (apair_ik_*.c, apair_ik4.c, apair_ik6r.c): the
 * complex type in C and C++, the Gaussian elimination they share (GAUSS_SOLVE), and the entry
 * points of the closed forms behind apair_ik_closed (apair_ik_closed.c). Not part of
 * the API (not installed; apair.h declares the solvers themselves).
 */
#ifndef APAIR_IK_INTERNAL_H
#define APAIR_IK_INTERNAL_H

#include <math.h>
#include <string.h>

#ifdef __cplusplus /* the library also builds as C++: std::complex in place of C99's complex type */
#include <complex>
typedef std::complex<double> cplx;
#define I cplx(0.0, 1.0)
#define creal(z) std::real(z)
#define cimag(z) std::imag(z)
#define cabs(z) std::abs(z)
#define cexp(z) std::exp(z)
#define catan(z) std::atan(z)
#define ccos(z) std::cos(z)
#define csin(z) std::sin(z)
#define clog(z) std::log(z)
#define csqrt(z) std::sqrt(z)
#define conj(z) std::conj(z)
#else
#include <complex.h>
typedef double _Complex cplx;
#endif

#include "apair.h"
#include "apair_internal.h"

#define NMAX 6 /* the most joints of a chain */

/* The closed forms' DH steps (static inline: every solver's file may take them) */
#define CLOSED_PI 3.14159265358979323846

static inline void closed_dh4(double a, double ca, double sa, double c, double psi, double *A) /* Rz(psi) Tz(c) Tx(a) Rx(alpha), 3 x 4 */
{
    double ct = cos(psi), st = sin(psi);
    double m[12] = {ct, -st * ca, st * sa, a * ct, st, ct * ca, -ct * sa, a * st, 0.0, sa, ca, c};
    memcpy(A, m, sizeof m);
}

static inline void closed_mul34(const double *A, const double *B, double *C) /* rigid 3 x 4 products */
{
    double t[12];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++)
            t[4 * r + k] = A[4 * r] * B[k] + A[4 * r + 1] * B[4 + k] + A[4 * r + 2] * B[8 + k] + (k == 3 ? A[4 * r + 3] : 0.0);
    memcpy(C, t, sizeof t);
}

static inline void closed_inv34(const double *A, double *B) /* the inverse of a rigid 3 x 4 transform (B != A) */
{
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++) B[4 * r + k] = A[4 * k + r];
        B[4 * r + 3] = -(A[r] * A[3] + A[4 + r] * A[7] + A[8 + r] * A[11]);
    }
}

static inline double closed_wrap(double x) /* into (-pi, pi], as apair.ik.poses.wrap */
{
    return x - 2 * CLOSED_PI * ceil((x - CLOSED_PI) / (2 * CLOSED_PI));
}

/* the solutions of one pose ascending by joint 1, then 2, ... (apair.ik.poses.refine's order) */
static inline void closed_sort(double *qj, double *ej, int found)
{
    for (int a = 1; a < found; a++)
        for (int b = a; b > 0; b--) {
            double *u = qj + 6 * (b - 1), *v = qj + 6 * b;
            int k = 0;
            while (k < 6 && u[k] == v[k]) k++;
            if (k == 6 || u[k] < v[k]) break;
            double t[6], te = ej[b - 1];
            memcpy(t, u, sizeof t); memcpy(u, v, sizeof t); memcpy(v, t, sizeof t);
            ej[b - 1] = ej[b]; ej[b] = te;
        }
}

/* The closed forms of six R-pairs (apair_ik_wrist.c, apair_ik_parallel.c, apair_ik_three_parallel.c; their shared steps in
 * apair_ik_closed.h). */
#define CLOSED_MAX 8 /* the most solutions kept per pose (a 6R chain of these families has at most 8) */
/* Each closed form's design read once into `design` (apair_ik_closed's storage; 0, or -1 where the
 * form does not apply) and its solutions at one pose T (4 x 4 row-major): q (8 x 6, the first
 * *found rows set), error (8), and the candidates and flags of apair_ik_wrist, apair_ik_parallel.
 * apair_ik_closed_init and apair_ik_closed_solve (apair_ik_closed.c) call them. */
int apair_ik_wrist_prepare(void *design, const double *dh, double scale);
void apair_ik_wrist_solve1(const void *design, const double *T, double tol, double *q, double *error, int *found,
                           int *candidates, int *flags);
int apair_ik_parallel_prepare(void *design, const double *dh, double scale);
void apair_ik_parallel_solve1(const void *design, const double *T, double tol, double *q, double *error, int *found,
                              int *candidates, int *flags);
int apair_ik_parallel_apair_prepare(void *design, const double *dh, double amplitude, double scale);
void apair_ik_parallel_apair_solve1(const void *design, const double *T, double tol, double *q, double *error,
                                    int *found, int *candidates, int *flags);
int apair_ik_parallel_slides_prepare(void *design, const double *dh, const double *amplitude, double scale);
void apair_ik_parallel_slides_solve1(const void *design, const double *T, double tol, double *q, double *error,
                                     int *found, int *candidates, int *flags);
int apair_ik_wrist_apair_prepare(void *design, const double *dh, double amplitude, double scale);
void apair_ik_wrist_apair_solve1(const void *design, const double *T, double tol, double *q, double *error, int *found,
                                 int *candidates, int *flags);
int apair_ik_wrist_slide1_prepare(void *design, const double *dh, double amplitude, double scale);
void apair_ik_wrist_slide1_solve1(const void *design, const double *T, double tol, double *q, double *error, int *found,
                                  int *candidates, int *flags);
/* the A-pair arms: at most 24 (UR, joint 3), 32 (UR, joints 1 and 5), 16 (a wrist, joint 3 or 1) */
#define CLOSED_APAIR_MAX APAIR_IK_APAIR_MAX
int apair_ik_three_parallel_prepare(void *design, const double *dh, double scale);
void apair_ik_three_parallel_solve1(const void *design, const double *T, double tol, double *q, double *error,
                                    int *found, int *candidates, int *flags);

/* GAUSS_SOLVE(name, T, mag) defines `static int name(int n, T *A, int m, T *B)` for the scalar
 * type T (mag: its absolute value). It solves A X = B (A n x n, row-major, overwritten; B n x m,
 * row-major, becomes X) by Gaussian elimination with partial pivoting. Returns 0, or -1 if a pivot
 * is zero or not finite. Each file defines the solvers it calls (static: the compiler inlines them
 * where it pays, as in one file). */
#define GAUSS_SOLVE(name, T, mag) \
    static int name(int n, T *A, int m, T *B) \
    { \
        for (int k = 0; k < n; k++) { \
            int p = k; \
            double best = mag(A[k * n + k]); \
            for (int r = k + 1; r < n; r++) { \
                double a = mag(A[r * n + k]); \
                if (a > best) { best = a; p = r; } \
            } \
            if (!(best > 0.0) || !isfinite(best)) return -1; \
            if (p != k) { \
                for (int c = 0; c < n; c++) { T t = A[k * n + c]; A[k * n + c] = A[p * n + c]; A[p * n + c] = t; } \
                for (int j = 0; j < m; j++) { T t = B[k * m + j]; B[k * m + j] = B[p * m + j]; B[p * m + j] = t; } \
            } \
            T inv = 1.0 / A[k * n + k]; \
            for (int r = k + 1; r < n; r++) { \
                T f = A[r * n + k] * inv; \
                if (f == 0.0) continue; \
                for (int c = k + 1; c < n; c++) A[r * n + c] -= f * A[k * n + c]; \
                for (int j = 0; j < m; j++) B[r * m + j] -= f * B[k * m + j]; \
            } \
        } \
        for (int k = n - 1; k >= 0; k--) \
            for (int j = 0; j < m; j++) { \
                T s = B[k * m + j]; \
                for (int c = k + 1; c < n; c++) s -= A[k * n + c] * B[c * m + j]; \
                B[k * m + j] = s / A[k * n + k]; \
            } \
        return 0; \
    }

#endif

/*
 * A copy of src/csrc/apair_ik.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik.c. Content hash: 04973d3e127b78b5
 */
/*
 * The inverse-kinematics solvers on the generated kernels: path tracking of the homotopy system
 * ik_system6 (all solutions, driven by apair.homotopy), the 6R elimination's back-substitution
 * and Newton's method on ik_system6 at a fixed pose (apair.ik6r), and a damped least-squares local solver
 * on fk<n> and jacobian<n> (the kernels of derivations/chain_ik.py and derivations/chain_kinematics.py).
 * Hand-written C: the C backend of codegen copies it into generated/c, the library it belongs to.
 * Its functions are declared in apair.h (template: codegen/backends/c/templates/apair.h.j2).
 */
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

#define NMAX 6
#define NV 7 /* variables of the trace test's slice system: the angles and lambda */
#define INV_MAX APAIR_IK_SYSTEM6_INVARIANTS /* the invariants of ik_system6 (apair.h) */
#define INV_RES APAIR_IK_RESIDUAL6_INVARIANTS
#define WIDE_STEP 1e-4 /* the step in tau below which a stall while tracking may turn extended precision on */
#define FAR 4.0 /* |Im theta| beyond which Newton's rounding floor in double may exceed the tracking tolerance */

/* ---------------------------------------------------------------- small dense linear algebra */

/* GAUSS_SOLVE(name, T, mag) defines `static int name(int n, T *A, int m, T *B)` for the scalar
 * type T (mag: its absolute value). It solves A X = B (A n x n, row-major, overwritten; B n x m,
 * row-major, becomes X) by Gaussian elimination with partial pivoting. Returns 0, or -1 if a pivot
 * is zero or not finite. */
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

/* Solves A X = B for complex A and B (see GAUSS_SOLVE). */
GAUSS_SOLVE(csolve_m, cplx, cabs)

/* Solves A x = b (n x n, row-major, overwritten); b becomes x. */
static int csolve(int n, cplx *A, cplx *b) { return csolve_m(n, A, 1, b); }

static double cnorm(int n, const cplx *x)
{
    double m = 0.0;
    for (int i = 0; i < n; i++) { double a = cabs(x[i]); if (a > m) m = a; }
    return m;
}

/* ---------------------------------------------------------------- the homotopy */

typedef struct {
    const apair_ik_problem *pb;
    const apair_kernel *sys, *law[2];
    double inv[INV_MAX];
    double inv_res[INV_RES];          /* ik_residual6's invariants, for residual_wide */
    double h[NMAX];                   /* the amplitudes (0 for an R-pair), ik_residual6's input */
    cplx p0[7], dp[7], gamma;
    int nv;                            /* variables: the n angles, or n + 1 with a slice */
    const apair_ik_slice *slice; /* NULL: H = F(theta; p(s)); else the slice system */
} tracker;

static cplx pair_at(const double *x, int k) { return x[2 * k] + I * x[2 * k + 1]; }

/* s(tau) = gamma tau / (1 + (gamma - 1) tau) and ds/dtau (if ds is not NULL). */
static cplx path_s(const tracker *tr, double tau, cplx *ds)
{
    cplx den = 1.0 + (tr->gamma - 1.0) * tau;
    if (ds) *ds = tr->gamma / (den * den);
    return tr->gamma * tau / den;
}

/* Coordinate k of the pose at v and s: p0 + s dp, or on a slice p + lambda w. */
static cplx pose_at(const tracker *tr, const cplx *v, cplx s, int k)
{
    const apair_ik_slice *sl = tr->slice;
    return sl ? pair_at(sl->p, k) + v[tr->pb->n] * pair_at(sl->w, k) : tr->p0[k] + s * tr->dp[k];
}

/* The slice's joint j at s: z = exp(i k theta_j) (k = 1/2 for an A-pair, 1 for an R-pair) and the
 * coefficients a, b of z and 1/z in l_s. Returns k. */
static double slice_term(const tracker *tr, const cplx *v, cplx s, int j, cplx *z, cplx *a, cplx *b)
{
    const apair_ik_slice *sl = tr->slice;
    int n = tr->pb->n;
    double k = tr->pb->kind[j] ? 0.5 : 1.0;
    *z = cexp(I * k * v[j]);
    *a = pair_at(sl->ell, j) + s * pair_at(sl->dell, j);
    *b = pair_at(sl->ell, n + j) + s * pair_at(sl->dell, n + j);
    return k;
}

/* H(theta, tau) = F(theta; p(s)) with p(s) = p0 + s (p1 - p0), s = gamma tau / (1 + (gamma - 1) tau);
 * Hv = dH/dtheta (n x n), Ht = dH/dtau; the law kernels take exp(i theta / 2). With a slice, the
 * slice system in (theta, lambda) (nv x nv). Returns -1 if a value is not finite. */
static int eval(const tracker *tr, const cplx *v, double tau, cplx *H, cplx *Hv, cplx *Ht)
{
    const apair_ik_problem *pb = tr->pb;
    const apair_ik_slice *sl = tr->slice;
    int n = pb->n;
    double law[NMAX * 8];
    for (int i = 0; i < n; i++) {
        cplx z = cexp(0.5 * I * v[i]);
        double vin[2] = {creal(z), cimag(z)}, out[8];
        const double *in[2] = {vin, pb->pair + 2 * i};
        double *outs[1] = {out};
        tr->law[pb->kind[i] != 0]->eval(in, outs);
        memcpy(law + 8 * i, out, 8 * sizeof(double));
    }
    cplx ds, s = path_s(tr, tau, &ds);
    double target[14], dir[14];
    for (int k = 0; k < 7; k++) {
        /* on a slice the derivative is along w (F is linear in the pose) */
        cplx t = pose_at(tr, v, s, k), d = sl ? pair_at(sl->w, k) : tr->dp[k];
        target[2 * k] = creal(t);
        target[2 * k + 1] = cimag(t);
        dir[2 * k] = creal(d);
        dir[2 * k + 1] = cimag(d);
    }
    double F[12], dF[6 * NMAX * 2], dFs[12];
    const double *in[4] = {law, target, dir, pb->dh};
    double *out[3] = {F, dF, dFs};
    if (tr->sys->n_invariants)
        tr->sys->core(tr->inv, in, out);
    else
        tr->sys->eval(in, out);
    int nv = tr->nv;
    for (int r = 0; r < 6; r++) {
        H[r] = F[2 * r] + I * F[2 * r + 1];
        for (int i = 0; i < n; i++)
            Hv[r * nv + i] = dF[2 * (r * n + i)] + I * dF[2 * (r * n + i) + 1];
        if (sl) {
            Hv[r * nv + n] = dFs[2 * r] + I * dFs[2 * r + 1];
            Ht[r] = 0.0;
        } else {
            Ht[r] = (dFs[2 * r] + I * dFs[2 * r + 1]) * ds;
        }
    }
    if (sl) { /* the slice's last equation (l_s - 1) mu + t0 + s dt */
        cplx lam = v[n], mu = sl->times_lambda ? lam : 1.0, l = 0.0, dl = 0.0;
        for (int j = 0; j < n; j++) {
            cplx z, a, b;
            double k = slice_term(tr, v, s, j, &z, &a, &b);
            cplx zi = 1.0 / z;
            l += a * z + b * zi;
            dl += pair_at(sl->dell, j) * z + pair_at(sl->dell, n + j) * zi;
            Hv[n * nv + j] = I * k * (a * z - b * zi) * mu;
        }
        H[n] = (l - 1.0) * mu + pair_at(sl->t0, 0) + s * pair_at(sl->dt, 0);
        Hv[n * nv + n] = sl->times_lambda ? l - 1.0 : 0.0;
        Ht[n] = (dl * mu + pair_at(sl->dt, 0)) * ds;
    }
    for (int r = 0; r < nv; r++)
        if (!isfinite(creal(H[r])) || !isfinite(cimag(H[r]))) return -1;
    return 0;
}

/* H of eval with the residual in extended precision (apair_wide): F from ik_residual6_wide at
 * z = exp(i theta / 2), and the slice's equation summed in apair_wide. Far out in the complex the
 * terms of H that cancel are exp(2 |Im theta|) larger than H; in double, Newton stalls there. The
 * values z, the pose and the slice's coefficients are the double ones (H is exact at them). */
static int residual_wide(const tracker *tr, const cplx *v, double tau, cplx *H)
{
    const apair_ik_problem *pb = tr->pb;
    const apair_ik_slice *sl = tr->slice;
    int n = pb->n;
    apair_wide z[2 * NMAX], target[14], F[12];
    for (int i = 0; i < n; i++) {
        cplx e = cexp(0.5 * I * v[i]);
        z[2 * i] = creal(e);
        z[2 * i + 1] = cimag(e);
    }
    cplx s = path_s(tr, tau, NULL);
    for (int k = 0; k < 7; k++) {
        cplx t = pose_at(tr, v, s, k);
        target[2 * k] = creal(t);
        target[2 * k + 1] = cimag(t);
    }
    apair_internal_ik_residual6_wide(tr->inv_res, z, tr->h, target, pb->dh, F);
    for (int r = 0; r < 6; r++) H[r] = (double)F[2 * r] + I * (double)F[2 * r + 1];
    if (sl) { /* (l_s - 1) mu + t0 + s dt, l_s = sum a_j z_j + b_j / z_j */
        apair_wide lr = -1.0, li = 0.0;
        for (int j = 0; j < n; j++) {
            cplx e, a, b;
            slice_term(tr, v, s, j, &e, &a, &b);
            apair_wide zr = creal(e), zi = cimag(e), m = zr * zr + zi * zi;
            apair_wide ar = creal(a), ai = cimag(a), br = creal(b), bi = cimag(b);
            lr += ar * zr - ai * zi + (br * zr + bi * zi) / m; /* b / z = b conj(z) / |z|^2 */
            li += ar * zi + ai * zr + (bi * zr - br * zi) / m;
        }
        cplx mu = sl->times_lambda ? v[n] : 1.0, c = pair_at(sl->t0, 0) + s * pair_at(sl->dt, 0);
        apair_wide mr = creal(mu), mi = cimag(mu);
        H[n] = (double)(lr * mr - li * mi + (apair_wide)creal(c)) + I * (double)(lr * mi + li * mr + (apair_wide)cimag(c));
    }
    for (int r = 0; r < tr->nv; r++)
        if (!isfinite(creal(H[r])) || !isfinite(cimag(H[r]))) return -1;
    return 0;
}

/* The largest |Im theta_i| of a point (its angles: lambda is no angle). */
static double far_of(const tracker *tr, const cplx *v)
{
    double far = 0.0;
    for (int i = 0; i < tr->pb->n; i++) far = fmax(far, fabs(cimag(v[i])));
    return far;
}

/* dv/dtau at (v, tau): Hv v' = -Ht. */
static int tangent(const tracker *tr, const cplx *v, double tau, cplx *k)
{
    int n = tr->nv;
    cplx H[NV], Hv[NV * NV], Ht[NV];
    if (eval(tr, v, tau, H, Hv, Ht)) return -1;
    for (int i = 0; i < n; i++) k[i] = -Ht[i];
    return csolve(n, Hv, k);
}

/* Newton's method on H(., tau) from v (updated in place): 1 if ||dv|| <= tol (1 + ||v||) within
 * `iters` steps, each at most half the one before. *last: the last step's size. k (if not NULL):
 * the tangent dv/dtau at the last point evaluated, from the same factorisation (that point is
 * within the last step of v, so the next predictor step can start from it). *wide: whether the
 * residual is taken in extended precision; a step that stalls far out (|Im theta| > far_wide)
 * above 1e3 tol turns it on, and two more steps are granted (the Jacobian stays double: its
 * relative error is far below 1, so Newton still converges, to the double rounding of v). */
static int correct(const tracker *tr, cplx *v, double tau, int iters, double tol, double far_wide, double *last,
                   cplx *k, int *wide)
{
    int n = tr->nv;
    double prev = INFINITY;
    for (int it = 0; it < iters; it++) {
        cplx H[NV], Hv[NV * NV], Ht[NV], B[2 * NV];
        if (eval(tr, v, tau, H, Hv, Ht)) return 0;
        if (*wide && residual_wide(tr, v, tau, H)) return 0;
        for (int i = 0; i < n; i++) { B[2 * i] = -H[i]; B[2 * i + 1] = -Ht[i]; }
        if (csolve_m(n, Hv, 2, B)) return 0;
        for (int i = 0; i < n; i++) H[i] = B[2 * i];
        if (k)
            for (int i = 0; i < n; i++) k[i] = B[2 * i + 1];
        double d = cnorm(n, H);
        for (int i = 0; i < n; i++) v[i] += H[i];
        *last = d;
        if (d <= tol * (1.0 + cnorm(n, v))) return 1;
        if (it > 0 && d > 0.5 * prev) {
            /* Newton stalls at the rounding floor: far out the products of cos and sin of theta
             * that cancel in H are exp(2 |Im theta|) large. Keep tracking there if the floor is
             * small (the endpoint must still meet the strict tolerance), else go on in extended
             * precision. */
            double far = far_of(tr, v);
            if (!*wide && far > FAR && d <= 1e3 * tol * (1.0 + cnorm(n, v))) return 1;
            if (*wide || !(far > far_wide)) return 0;
            *wide = 1;
            iters = it + 3;
        }
        prev = d;
    }
    return 0;
}

/* 1-norm condition number of Hv at (v, 1), from its inverse. */
static double condition(const tracker *tr, const cplx *v)
{
    int n = tr->nv;
    cplx H[NV], Hv[NV * NV], Ht[NV], A[NV * NV];
    if (eval(tr, v, 1.0, H, Hv, Ht)) return INFINITY;
    double norm = 0.0, inorm = 0.0;
    for (int c = 0; c < n; c++) {
        double s = 0.0;
        for (int r = 0; r < n; r++) s += cabs(Hv[r * n + c]);
        if (s > norm) norm = s;
    }
    for (int c = 0; c < n; c++) {
        cplx e[NV];
        for (int r = 0; r < n; r++) e[r] = 0.0;
        e[c] = 1.0;
        memcpy(A, Hv, sizeof(cplx) * n * n);
        if (csolve(n, A, e)) return INFINITY;
        double s = 0.0;
        for (int r = 0; r < n; r++) s += cabs(e[r]);
        if (s > inorm) inorm = s;
    }
    return norm * inorm;
}

/* Whether the endpoint v (at tau = 1, far out) is a regular root although Hv's condition number
 * is large. In the angles the condition number of a point far out is large at regular roots too
 * (the values that cancel in H are exp(2 |Im theta|) large), so the test is Newton's: from v moved
 * by 1e-7 (1 + ||v||), four steps with the residual in extended precision must come back to v to
 * final_tol. They do when the convergence is quadratic; at a multiple root it is linear (each step
 * about half the one before, at a double root). */
static int regular_far(const tracker *tr, const apair_ik_options *opt, const cplx *v)
{
    int n = tr->nv, wide = 1;
    double size = 1.0 + cnorm(n, v), d = INFINITY;
    cplx q[NV], e[NV];
    for (int i = 0; i < n; i++) q[i] = v[i] + 1e-7 * size * ((i % 2) ? 1.0 : I);
    for (int it = 0; it < 4 && !(d <= opt->final_tol * size); it++)
        if (!correct(tr, q, 1.0, 1, opt->final_tol, 0.0, &d, NULL, &wide) && !isfinite(d)) return 0;
    for (int i = 0; i < n; i++) e[i] = q[i] - v[i];
    return d <= opt->final_tol * size && cnorm(n, e) <= 1e-10 * size;
}

/* One path from tau = 0 to 1: RK4 predictor, Newton corrector, step size halved on failure and
 * grown after successes; at tau = 1 Newton to full accuracy. A step costs four evaluations plus
 * the corrector's: its first stage is the last corrector iteration's tangent. */
static int track_path(const tracker *tr, const apair_ik_options *opt, cplx *v, int *steps, double *cond)
{
    int n = tr->nv;
    double tau = 0.0, h = opt->initial_step, last = 0.0;
    int good = 0, have_k1 = 0, wide = 0, wide_steps = 0;
    cplx k1[NV];  /* dv/dtau at (v, tau): kept across a failed step, taken from the corrector after one */
    *steps = 0;
    *cond = INFINITY;
    while (tau < 1.0) {
        if (++*steps > opt->max_steps) return APAIR_PATH_TOO_LONG;
        double hh = fmin(h, 1.0 - tau);
        cplx k2[NV], k3[NV], k4[NV], w[NV], p[NV], knext[NV];
        int ok = have_k1 || tangent(tr, v, tau, k1) == 0;
        have_k1 = ok;
        if (ok) { for (int i = 0; i < n; i++) w[i] = v[i] + 0.5 * hh * k1[i]; ok = tangent(tr, w, tau + 0.5 * hh, k2) == 0; }
        if (ok) { for (int i = 0; i < n; i++) w[i] = v[i] + 0.5 * hh * k2[i]; ok = tangent(tr, w, tau + 0.5 * hh, k3) == 0; }
        if (ok) { for (int i = 0; i < n; i++) w[i] = v[i] + hh * k3[i]; ok = tangent(tr, w, tau + hh, k4) == 0; }
        if (ok) {
            for (int i = 0; i < n; i++) p[i] = v[i] + hh / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            /* extended precision only once the step has shrunk: most stalls far out are steps too long */
            ok = correct(tr, p, tau + hh, opt->corrector_steps, opt->path_tol, hh < WIDE_STEP ? opt->wide_track : INFINITY,
                         &last, knext, &wide);
            /* a path that crawls far out (each step in extended precision, the predictor's double
             * tangents too inexact for long steps) is given up: with a new gamma it takes another way */
            if (wide && ++wide_steps > opt->wide_steps) return APAIR_PATH_TOO_LONG;
        }
        if (ok) {
            memcpy(v, p, n * sizeof(cplx));
            double far = far_of(tr, v);
            if (!(far > opt->wide_track)) wide = 0;
            memcpy(k1, knext, n * sizeof(cplx));  /* the next step's first stage, from the corrector */
            tau = (hh == 1.0 - tau) ? 1.0 : tau + hh;
            if (++good >= 2) { h = fmin(2.0 * h, opt->max_step); good = 0; }
            if (far > opt->divergence) return APAIR_PATH_DIVERGED;
        } else {
            h *= 0.5;
            good = 0;
            if (h < opt->min_step) return APAIR_PATH_FAILED;
        }
    }
    /* the endpoint: Newton at tau = 1 until its step stops shrinking (or reaches final_tol); far
     * out, once it stalls, on with the residual in extended precision */
    double prev = INFINITY;
    for (int it = 0; it < opt->final_steps; it++) {
        double d = INFINITY;
        cplx q[NV];
        memcpy(q, v, n * sizeof(cplx));
        int done = correct(tr, q, 1.0, 1, opt->final_tol, opt->wide_end, &d, NULL, &wide);
        if (!isfinite(d)) break;
        if (d >= prev) {
            if (wide || !(far_of(tr, v) > opt->wide_end)) break;
            wide = 1;
            prev = INFINITY;
            continue;
        }
        memcpy(v, q, n * sizeof(cplx));
        prev = d;
        if (done) break;
    }
    int converged = prev <= opt->path_tol * (1.0 + cnorm(n, v));
    *cond = condition(tr, v);
    for (int i = 0; i < n; i++)
        if (!isfinite(creal(v[i])) || !isfinite(cimag(v[i]))) return APAIR_PATH_DIVERGED;
    double far = far_of(tr, v);
    if (far > opt->divergence) return APAIR_PATH_DIVERGED;
    if (!converged || (*cond > opt->singular_cond && !(far > opt->wide_end && regular_far(tr, opt, v))))
        return APAIR_PATH_SINGULAR;
    return APAIR_PATH_OK;
}

void apair_ik_default_options(apair_ik_options *opt)
{
    opt->initial_step = 0.1;
    opt->max_step = 0.5;
    opt->min_step = 1e-12;
    opt->max_steps = 500;
    opt->corrector_steps = 3;
    opt->path_tol = 1e-7;
    opt->final_tol = 1e-14;
    opt->final_steps = 30;
    opt->divergence = 40.0;
    opt->singular_cond = 1e10;
    opt->wide_track = 4.0;
    opt->wide_end = 4.0;
    opt->wide_steps = 500;
}

/* The tracker of problem pb from the pose p0 to p1 (7 complex each, as 14 doubles) with gamma:
 * its kernels, and the design's invariants computed once. Returns 0, or -1 for a bad problem. */
static int setup(tracker *tr, const apair_ik_problem *pb, const double *p0, const double *p1, cplx gamma)
{
    if (pb->n != NMAX) return -1;
    tr->pb = pb;
    tr->sys = apair_find_kernel("ik_system6");
    tr->law[0] = apair_find_kernel("ik_law_revolute");
    tr->law[1] = apair_find_kernel("ik_law_sinusoidal");
    if (!tr->sys || !tr->law[0] || !tr->law[1] || tr->sys->n_invariants > INV_MAX) return -1;
    for (int i = 0; i < pb->n; i++)
        if (pb->kind[i] != 0 && pb->kind[i] != 1) return -1;
    if (tr->sys->n_invariants) {
        const double *in[4] = {NULL, NULL, NULL, pb->dh};
        tr->sys->invariants(in, tr->inv);
    }
    for (int i = 0; i < pb->n; i++) tr->h[i] = pb->kind[i] ? pb->pair[2 * i] : 0.0;
    apair_ik_residual6_invariants(tr->h, pb->dh, tr->inv_res);
    for (int k = 0; k < 7; k++) {
        tr->p0[k] = p0[2 * k] + I * p0[2 * k + 1];
        tr->dp[k] = (p1[2 * k] + I * p1[2 * k + 1]) - tr->p0[k];
    }
    tr->gamma = gamma;
    tr->nv = pb->n;
    tr->slice = NULL;
    return 0;
}

/* Tracks every start point from s = 0 to 1 with the tracker tr, end/status/steps/cond per path. */
static void track_all(const tracker *tr, const apair_ik_options *opt, size_t count, const double *start,
                      double *end, int *status, int *steps, double *cond)
{
    int n = tr->nv;
    for (size_t j = 0; j < count; j++) {
        cplx v[NV];
        for (int i = 0; i < n; i++) v[i] = start[2 * (j * n + i)] + I * start[2 * (j * n + i) + 1];
        status[j] = track_path(tr, opt, v, steps + j, cond + j);
        for (int i = 0; i < n; i++) {
            end[2 * (j * n + i)] = creal(v[i]);
            end[2 * (j * n + i) + 1] = cimag(v[i]);
        }
    }
}

int apair_ik_track(const apair_ik_problem *pb, const apair_ik_options *opt, const double *p0,
                   const double *p1, const double *gamma, size_t count, const double *start, double *end,
                   int *status, int *steps, double *cond)
{
    tracker tr;
    if (setup(&tr, pb, p0, p1, gamma[0] + I * gamma[1])) return -1;
    track_all(&tr, opt, count, start, end, status, steps, cond);
    return 0;
}

int apair_ik_track_slice(const apair_ik_problem *pb, const apair_ik_options *opt,
                         const apair_ik_slice *sl, const double *gamma, size_t count, const double *start,
                         double *end, int *status, int *steps, double *cond)
{
    tracker tr;
    if (setup(&tr, pb, sl->p, sl->p, gamma[0] + I * gamma[1])) return -1;
    tr.nv = pb->n + 1;
    tr.slice = sl;
    track_all(&tr, opt, count, start, end, status, steps, cond);
    return 0;
}

int apair_ik_newton(const apair_ik_problem *pb, const double *p, size_t count, double *theta, int max_steps,
                    double tol, double floor, double stall, double imag_max, double *size)
{
    tracker tr;
    if (setup(&tr, pb, p, p, 1.0)) return -1;
    int n = pb->n;
    for (size_t j = 0; j < count; j++) {
        cplx v[NMAX];
        double d = INFINITY, prev = INFINITY;
        for (int i = 0; i < n; i++) v[i] = theta[2 * (j * n + i)] + I * theta[2 * (j * n + i) + 1];
        for (int it = 0; it < max_steps; it++) {
            cplx H[NMAX], Hv[NMAX * NMAX], Ht[NMAX];
            if (eval(&tr, v, 1.0, H, Hv, Ht) || csolve(n, Hv, H)) { d = INFINITY; break; }
            prev = d;
            d = cnorm(n, H);
            int out = !isfinite(d);
            for (int i = 0; i < n; i++) {
                v[i] -= H[i];
                out |= !(fabs(cimag(v[i])) <= imag_max);
            }
            if (out) { d = INFINITY; break; }
            if (d <= tol || (d <= floor && d > stall * prev)) break;  /* converged, or at its rounding floor */
        }
        size[j] = d;
        for (int i = 0; i < n; i++) {
            theta[2 * (j * n + i)] = creal(v[i]);
            theta[2 * (j * n + i) + 1] = cimag(v[i]);
        }
    }
    return 0;
}

/* ---------------------------------------------------------------- the 6R elimination's roots */

/* The complex psi with (cos psi, sin psi) proportional to (c, s). */
static cplx angle_of(cplx c, cplx s) { return -I * clog((c + I * s) / csqrt(c * c + s * s)); }

int apair_ik6r_angles(size_t count, const double *x3, const double *vec, const double *P, const double *L,
                      const double *sigma, const double *dh, const double *T, double *theta)
{
    for (size_t j = 0; j < count; j++) {
        cplx x = x3[2 * j] + I * x3[2 * j + 1], V[12];
        int half = cabs(x) <= 1.0 ? 0 : 12;  /* [v; x3 v]: the half with the larger norm */
        for (int k = 0; k < 12; k++) V[k] = vec[2 * (24 * j + half + k)] + I * vec[2 * (24 * j + half + k) + 1];
        /* V[3 i + j] ~ x4^i x5^j: x4 and x5 as least-squares ratios of shifted entries */
        cplx n4 = 0.0, n5 = 0.0;
        double d4 = 0.0, d5 = 0.0;
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < 3; b++) {
                cplx v = V[3 * a + b];
                double m = creal(v) * creal(v) + cimag(v) * cimag(v);
                if (a < 3) { n4 += conj(v) * V[3 * (a + 1) + b]; d4 += m; }
                if (b < 2) { n5 += conj(v) * V[3 * a + b + 1]; d5 += m; }
            }
        cplx psi[6], cs[3][3];
        psi[2] = sigma[0] + 2.0 * catan(x);
        psi[3] = sigma[1] + 2.0 * catan(n4 / d4);
        psi[4] = sigma[2] + 2.0 * catan(n5 / d5);
        for (int k = 0; k < 3; k++) { cs[k][0] = 1.0; cs[k][1] = ccos(psi[2 + k]); cs[k][2] = csin(psi[2 + k]); }
        /* X12 (without its constant) = L^T P (1, c3, s3) (x) (1, c4, s4) (x) (1, c5, s5) */
        cplx rhs[14], X12[8];
        for (int r = 0; r < 14; r++) {
            cplx acc = 0.0;
            for (int m = 0; m < 27; m++) acc += P[27 * r + m] * (cs[0][m / 9] * cs[1][(m / 3) % 3] * cs[2][m % 3]);
            rhs[r] = acc;
        }
        for (int c = 0; c < 8; c++) {
            cplx acc = 0.0;
            for (int r = 0; r < 14; r++) acc += rhs[r] * L[8 * r + c];
            X12[c] = acc;
        }
        /* X12 = (1, c1, s1) (x) (1, c2, s2) minus its constant: c2, s2 at 0, 1; c1, s1 at 2, 5 */
        psi[0] = angle_of(X12[2], X12[5]);
        psi[1] = angle_of(X12[0], X12[1]);
        /* psi6: A_6's first column (cos psi6, sin psi6, 0) = R_5^T ... R_1^T T e_x, R_i = Rz(psi_i) Rx(alpha_i) */
        cplx u0 = T[0], u1 = T[4], u2 = T[8];
        for (int i = 0; i < 5; i++) {
            cplx c = ccos(psi[i]), s = csin(psi[i]), t;
            double ca = cos(dh[4 * i + 1]), sa = sin(dh[4 * i + 1]);
            t = c * u0 + s * u1; u1 = c * u1 - s * u0; u0 = t;
            t = ca * u1 + sa * u2; u2 = ca * u2 - sa * u1; u1 = t;
        }
        psi[5] = angle_of(u0, u1);
        for (int i = 0; i < 6; i++) {
            cplx th = psi[i] - dh[4 * i + 3];
            theta[2 * (6 * j + i)] = creal(th);
            theta[2 * (6 * j + i) + 1] = cimag(th);
        }
    }
    return 0;
}

/* ---------------------------------------------------------------- the local solver */

#define LOCAL_INV_MAX 1024

/* The kernels of the local solver, with the design's invariants of fk and jacobian computed once. */
typedef struct {
    const apair_kernel *fk, *jac, *laws[3];
    double inv_fk[LOCAL_INV_MAX], inv_jac[LOCAL_INV_MAX];
} local_kernels;

/* fk(q) (4 x 4) and, if J, the geometric Jacobian (6 x n); -1 outside a pair's range. */
static int chain_eval(const local_kernels *lk, const apair_ik_chain *ch, const double *q, double *T, double *J)
{
    double law[NMAX * 5];
    for (int i = 0; i < ch->n; i++) {
        const double *in[3] = {q + i, ch->pair + 2 * i, ch->pair + 2 * i + 1};
        double *out[1] = {law + 5 * i};
        lk->laws[ch->kind[i]]->eval(in, out);
        for (int k = 0; k < 5; k++)
            if (!isfinite(law[5 * i + k])) return -1;
    }
    const double *in[2] = {law, ch->dh};
    double *outT[1] = {T};
    if (lk->fk->n_invariants) lk->fk->core(lk->inv_fk, in, outT); else lk->fk->eval(in, outT);
    if (J) {
        double *outJ[1] = {J};
        if (lk->jac->n_invariants) lk->jac->core(lk->inv_jac, in, outJ); else lk->jac->eval(in, outJ);
    }
    return 0;
}

/* e = [(t_T - t) / scale; 1/2 sum_k R e_k x R_T e_k]: zero exactly at fk = T for rotations that
 * differ by less than pi; and the largest entry of |fk - T|. */
static double pose_error(const double *T, const double *target, double scale, double *e)
{
    double worst = 0.0;
    for (int k = 0; k < 12; k++) { double d = fabs(T[k] - target[k]); if (d > worst) worst = d; }
    for (int r = 0; r < 3; r++) e[r] = (target[4 * r + 3] - T[4 * r + 3]) / scale;
    e[3] = e[4] = e[5] = 0.0;
    for (int k = 0; k < 3; k++) {
        double a[3] = {T[k], T[4 + k], T[8 + k]}, b[3] = {target[k], target[4 + k], target[8 + k]};
        e[3] += 0.5 * (a[1] * b[2] - a[2] * b[1]);
        e[4] += 0.5 * (a[2] * b[0] - a[0] * b[2]);
        e[5] += 0.5 * (a[0] * b[1] - a[1] * b[0]);
    }
    return worst;
}

static double sq(const double *e) { double s = 0.0; for (int k = 0; k < 6; k++) s += e[k] * e[k]; return s; }

int apair_ik_local(const apair_ik_chain *ch, size_t count, const double *target, ptrdiff_t target_stride,
                   const double *seed, ptrdiff_t seed_stride, double tol, int max_iter, double *q, double *residual,
                   int *converged)
{
    static const char *fks[NMAX] = {"fk1", "fk2", "fk3", "fk4", "fk5", "fk6"};
    static const char *jacs[NMAX] = {"jacobian1", "jacobian2", "jacobian3", "jacobian4", "jacobian5", "jacobian6"};
    int n = ch->n;
    if (n < 1 || n > NMAX) return -1;
    local_kernels lk;
    lk.fk = apair_find_kernel(fks[n - 1]);
    lk.jac = apair_find_kernel(jacs[n - 1]);
    lk.laws[0] = apair_find_kernel("law_revolute");
    lk.laws[1] = apair_find_kernel("law_sinusoidal");
    lk.laws[2] = apair_find_kernel("law_general");
    if (!lk.fk || !lk.jac || !lk.laws[0] || !lk.laws[1] || !lk.laws[2] || lk.fk->n_invariants > LOCAL_INV_MAX ||
        lk.jac->n_invariants > LOCAL_INV_MAX)
        return -1;
    {
        const double *in[2] = {NULL, ch->dh};
        if (lk.fk->n_invariants) lk.fk->invariants(in, lk.inv_fk);
        if (lk.jac->n_invariants) lk.jac->invariants(in, lk.inv_jac);
    }
    for (int i = 0; i < n; i++)
        if (ch->kind[i] < 0 || ch->kind[i] > 2) return -1;
    for (size_t j = 0; j < count; j++) {
        const double *Tt = target + (ptrdiff_t)j * target_stride;
        double *x = q + j * n;
        double T[16], J[6 * NMAX], e[6], trial[NMAX], eT[6];
        for (int i = 0; i < n; i++) x[i] = fmin(fmax(seed[(ptrdiff_t)j * seed_stride + i], ch->lower[i]), ch->upper[i]);
        converged[j] = 0;
        residual[j] = INFINITY;
        if (chain_eval(&lk, ch, x, T, J)) continue;
        double err = pose_error(T, Tt, ch->scale, e), cost = sq(e), lambda = 1e-3;
        for (int it = 0; it < max_iter && err > tol; it++) {
            /* (J^T J + lambda diag(J^T J) + lambda 1e-9) dq = J^T e, J with its v rows in units of scale */
            double A[NMAX * NMAX], g[NMAX];
            for (int a = 0; a < n; a++) {
                g[a] = 0.0;
                for (int r = 0; r < 6; r++) g[a] += J[r * n + a] * (r < 3 ? 1.0 / ch->scale : 1.0) * e[r];
                for (int b = 0; b < n; b++) {
                    double s = 0.0;
                    for (int r = 0; r < 6; r++) {
                        double w = r < 3 ? 1.0 / (ch->scale * ch->scale) : 1.0;
                        s += J[r * n + a] * J[r * n + b] * w;
                    }
                    A[a * n + b] = s;
                }
            }
            int accepted = 0;
            for (int tries = 0; tries < 12 && !accepted; tries++) {
                double M[NMAX * NMAX], d[NMAX];
                memcpy(M, A, sizeof M);
                for (int a = 0; a < n; a++) M[a * n + a] += lambda * (A[a * n + a] + 1e-9);
                /* Cholesky M = L L^T, then the two triangular solves */
                int ok = 1;
                for (int a = 0; a < n && ok; a++) {
                    for (int b = 0; b <= a; b++) {
                        double s = M[a * n + b];
                        for (int k = 0; k < b; k++) s -= M[a * n + k] * M[b * n + k];
                        if (a == b) { if (!(s > 0.0)) { ok = 0; break; } M[a * n + a] = sqrt(s); }
                        else M[a * n + b] = s / M[b * n + b];
                    }
                }
                if (!ok) { lambda *= 10.0; continue; }
                for (int a = 0; a < n; a++) { double s = g[a]; for (int k = 0; k < a; k++) s -= M[a * n + k] * d[k]; d[a] = s / M[a * n + a]; }
                for (int a = n - 1; a >= 0; a--) { double s = d[a]; for (int k = a + 1; k < n; k++) s -= M[k * n + a] * d[k]; d[a] = s / M[a * n + a]; }
                for (int i = 0; i < n; i++) trial[i] = fmin(fmax(x[i] + d[i], ch->lower[i]), ch->upper[i]);
                double Tn[16], Jn[6 * NMAX];
                if (chain_eval(&lk, ch, trial, Tn, Jn) == 0) {
                    double errn = pose_error(Tn, Tt, ch->scale, eT), costn = sq(eT);
                    if (costn < cost || errn < err) {
                        memcpy(x, trial, n * sizeof(double));
                        memcpy(T, Tn, sizeof T);
                        memcpy(J, Jn, sizeof(double) * 6 * n);
                        memcpy(e, eT, sizeof e);
                        err = errn;
                        cost = costn;
                        lambda = fmax(lambda / 10.0, 1e-12);
                        accepted = 1;
                        break;
                    }
                }
                lambda *= 10.0;
            }
            if (!accepted) break;
        }
        residual[j] = err;
        converged[j] = err <= tol;
    }
    return 0;
}

/* ---------------------------------------------------------------- the 4-joint elimination */

#define IK4_DEG 16   /* the largest degree of an image Q(W(u3, u4)) in u3 or u4 (two A-pairs: 8) */
#define IK4_N 32     /* the largest Sylvester size in u4 */

/* Solves A X = B for real A and B (see GAUSS_SOLVE). */
GAUSS_SOLVE(rsolve_m, double, fabs)

/* The image coefficients out[k][l] (k <= 2 d3, l <= 2 d4, row stride 2 d4 + 1) of W^T Q W for
 * W(u3, u4) = sum C[i][j] u3^i u4^j (C: (d3 + 1) x (d4 + 1) x 8), then divided by (1 + u3^2)^a3
 * and (1 + u4^2)^a4 (the recurrence q_k = p_k - q_{k-2}; the remainder, zero at every pose by
 * the design's factors, is dropped). The quotient keeps the row stride. */
static void ik4_image(int d3, int d4, const double *C, const double *Q, int a3, int a4, double *out)
{
    int n3 = 2 * d3 + 1, n4 = 2 * d4 + 1, m = (d3 + 1) * (d4 + 1);
    double QC[(IK4_DEG / 2 + 1) * (IK4_DEG / 2 + 1) * 8];
    for (int t = 0; t < m; t++)
        for (int a = 0; a < 8; a++) {
            double s = 0.0;
            for (int b = 0; b < 8; b++) s += Q[8 * a + b] * C[8 * t + b];
            QC[8 * t + a] = s;
        }
    for (int k = 0; k < n3 * n4; k++) out[k] = 0.0;
    for (int t = 0; t < m; t++)
        for (int s = 0; s < m; s++) {
            double v = 0.0;
            for (int a = 0; a < 8; a++) v += C[8 * t + a] * QC[8 * s + a];
            out[(t / (d4 + 1) + s / (d4 + 1)) * n4 + t % (d4 + 1) + s % (d4 + 1)] += v;
        }
    for (int e = 0, deg = n3 - 1; e < a3; e++, deg -= 2) /* along u3: rows */
        for (int k = 2; k <= deg - 2; k++)
            for (int l = 0; l < n4; l++) out[k * n4 + l] -= out[(k - 2) * n4 + l];
    for (int e = 0, deg = n4 - 1; e < a4; e++, deg -= 2) /* along u4: columns */
        for (int k = 0; k < n3; k++)
            for (int l = 2; l <= deg - 2; l++) out[k * n4 + l] -= out[k * n4 + l - 2];
}

/* G (G0 + 1) x (G1 + 1), row stride n4 (avail rows), becomes (G - a F) / (1 + u3^2) with a(u3, u4) = Re h(u4) +
 * u3 Im h(u4) where G(i, .) = F(i, .) h (least squares, normal equations; checked: relative
 * residual <= tol), so that G - a F vanishes at u3 = +-i; *G0 its new degree in u3. Returns 0, or
 * 2 where G(i, .) is not such a multiple (as _deflated in apair.ik). */
static int ik4_deflate(int n4, int avail, const double *F, int F0, int F1, double *G, int *G0, int G1, double tol)
{
    int k = G1 - F1;
    if (k < 0 || k >= IK4_N || (*G0 > F0 + 1 ? *G0 : F0 + 1) >= avail) return 2;
    cplx fi[IK4_DEG + 1], gi[IK4_DEG + 1], pw = 1.0;
    for (int c = 0; c <= IK4_DEG; c++) fi[c] = gi[c] = 0.0;
    for (int r = 0; r <= F0; r++, pw *= I)
        for (int c = 0; c <= F1; c++) fi[c] += F[r * n4 + c] * pw;
    pw = 1.0;
    for (int r = 0; r <= *G0; r++, pw *= I)
        for (int c = 0; c <= G1; c++) gi[c] += G[r * n4 + c] * pw;
    double gmax = 0.0;
    for (int c = 0; c <= G1; c++) gmax = fmax(gmax, cabs(gi[c]));
    if (!(gmax > 0.0)) return 2;
    cplx N[IK4_N * IK4_N], h[IK4_N]; /* (A^H A) h = A^H gi, A[j + c][j] = fi[c] */
    for (int p = 0; p <= k; p++) {
        for (int q = 0; q <= k; q++) {
            cplx t = 0.0;
            for (int c = 0; c <= F1; c++)
                if (c + p - q >= 0 && c + p - q <= F1) t += conj(fi[c]) * fi[c + p - q];
            N[p * (k + 1) + q] = t;
        }
        cplx t = 0.0;
        for (int c = 0; c <= F1; c++) t += conj(fi[c]) * gi[c + p];
        h[p] = t;
    }
    if (csolve(k + 1, N, h)) return 2;
    for (int r = 0; r <= G1; r++) {
        cplx t = -gi[r];
        for (int j = 0; j <= k; j++)
            if (r - j >= 0 && r - j <= F1) t += fi[r - j] * h[j];
        if (!(cabs(t) <= tol * gmax)) return 2;
    }
    int rows = *G0 > F0 + 1 ? *G0 : F0 + 1; /* the degree of G - a F in u3 */
    for (int r = *G0 + 1; r <= rows; r++)
        for (int c = 0; c <= G1; c++) G[r * n4 + c] = 0.0;
    for (int j = 0; j <= k; j++)
        for (int r = 0; r <= F0; r++)
            for (int c = 0; c <= F1; c++) {
                G[r * n4 + j + c] -= creal(h[j]) * F[r * n4 + c];
                G[(r + 1) * n4 + j + c] -= cimag(h[j]) * F[r * n4 + c];
            }
    for (int r = 2; r <= rows - 2; r++) /* divided by 1 + u3^2 (the remainder, ~ the residual, dropped) */
        for (int c = 0; c <= G1; c++) G[r * n4 + c] -= G[(r - 2) * n4 + c];
    *G0 = rows - 2;
    return 0;
}

int apair_ik4_pencil(int d3, int d4, const double *C, const double *Qf, const int *af, const double *Qg,
                     const int *ag, double cond_max, int deflate, double deflate_tol, double *f, double *g,
                     double *M, int *size)
{
    if (d3 < 1 || d4 < 1 || 2 * d3 > IK4_DEG || 2 * d4 > IK4_DEG) return -1;
    int n4 = 2 * d4 + 1;
    double F[(IK4_DEG + 1) * (IK4_DEG + 1)], G[(IK4_DEG + 1) * (IK4_DEG + 1)];
    ik4_image(d3, d4, C, Qf, af[0], af[1], F);
    ik4_image(d3, d4, C, Qg, ag[0], ag[1], G);
    int F0 = 2 * d3 - 2 * af[0], F1 = 2 * d4 - 2 * af[1], G0 = 2 * d3 - 2 * ag[0], G1 = 2 * d4 - 2 * ag[1];
    if (F0 < 1 || F1 < 0 || G0 < 1 || G1 < 0 || F1 + G1 < 1 || F1 + G1 > IK4_N) return -1;
    if ((deflate & 1) && ik4_deflate(n4, 2 * d3 + 1, F, F0, F1, G, &G0, G1, deflate_tol)) return 2;
    if (deflate & 2) { /* the same along u4: on the transposes */
        int m3 = 2 * d3 + 1;
        double Ft[(IK4_DEG + 1) * (IK4_DEG + 1)], Gt[(IK4_DEG + 1) * (IK4_DEG + 1)];
        for (int k = 0; k < m3; k++)
            for (int l = 0; l < n4; l++) { Ft[l * m3 + k] = F[k * n4 + l]; Gt[l * m3 + k] = G[k * n4 + l]; }
        if (ik4_deflate(m3, n4, Ft, F1, F0, Gt, &G1, G0, deflate_tol)) return 2;
        for (int k = 0; k < m3; k++)
            for (int l = 0; l < n4; l++) G[k * n4 + l] = Gt[l * m3 + k];
    }
    if (G0 < 1 || G1 < 0 || F1 + G1 < 1) return -1;
    for (int k = 0; k <= F0; k++)
        for (int l = 0; l <= F1; l++) f[k * (F1 + 1) + l] = F[k * n4 + l];
    for (int k = 0; k <= G0; k++)
        for (int l = 0; l <= G1; l++) g[k * (G1 + 1) + l] = G[k * n4 + l];
    /* the Sylvester rows in u4 (v^r f, r < G1, then v^r g, r < F1), each a polynomial in u3 of its
     * degree; row linearisation: z_{i,k} = u3^k w_i (k < d_i), columns lo_i + k */
    int N = F1 + G1, n = G1 * F0 + F1 * G0;
    *size = n;
    double lead[IK4_N * IK4_N], inv[IK4_N * IK4_N];
    for (int i = 0; i < N; i++) {
        int fr = i < G1, r = fr ? i : i - G1, d = fr ? F0 : G0, w = fr ? F1 : G1;
        const double *p = fr ? f : g;
        for (int c = 0; c < N; c++) lead[c * N + i] = (c >= r && c <= r + w) ? p[d * (w + 1) + c - r] : 0.0;
    }
    double norm = 0.0, inorm = 0.0;
    for (int i = 0; i < N; i++) {
        double s = 0.0;
        for (int c = 0; c < N; c++) s += fabs(lead[c * N + i]);
        if (s > norm) norm = s;
    }
    for (int i = 0; i < N * N; i++) inv[i] = (i % (N + 1) == 0) ? 1.0 : 0.0;
    if (rsolve_m(N, lead, N, inv)) return 1;
    for (int i = 0; i < N; i++) {
        double s = 0.0;
        for (int c = 0; c < N; c++) s += fabs(inv[c * N + i]);
        if (s > inorm) inorm = s;
    }
    if (!(norm * inorm < cond_max)) return 1;
    /* M = B^{-1} A: the shift rows M[lo_i + k][lo_i + k + 1] = 1, and in row lo_j + d_j - 1 (the
     * lead column of row j) row j of inv times A's last N rows (A[c][lo_i + k] = -row_i[k][c]) */
    int lo[IK4_N], deg[IK4_N];
    for (int i = 0, at = 0; i < N; i++) { deg[i] = i < G1 ? F0 : G0; lo[i] = at; at += deg[i]; }
    for (int k = 0; k < n * n; k++) M[k] = 0.0;
    for (int i = 0; i < N; i++) {
        int fr = i < G1, r = fr ? i : i - G1, w = fr ? F1 : G1;
        const double *p = fr ? f : g;
        for (int k = 0; k + 1 < deg[i]; k++) M[(lo[i] + k) * n + lo[i] + k + 1] = 1.0;
        for (int k = 0; k < deg[i]; k++)
            for (int j = 0; j < N; j++) {
                double s = 0.0;
                for (int c = r; c <= r + w; c++) s -= inv[j * N + c] * p[k * (w + 1) + c - r];
                M[(lo[j] + deg[j] - 1) * n + lo[i] + k] = s;
            }
    }
    return 0;
}

/* Singular values s (n, descending) and right singular vectors V (n x n, column k for s[k]) of A
 * (m x n, row-major, m >= n, overwritten by U S) by one-sided Jacobi rotations (Hestenes): accurate
 * null vectors of the small coefficient matrices below, without LAPACK. Returns 0, or -1 if it
 * did not converge. */
static int jacobi_svd(int m, int n, double *A, double *s, double *V)
{
    for (int i = 0; i < n * n; i++) V[i] = (i % (n + 1) == 0) ? 1.0 : 0.0;
    int done = 0;
    for (int sweep = 0; sweep < 60 && !done; sweep++) {
        done = 1;
        for (int p = 0; p < n - 1; p++)
            for (int q = p + 1; q < n; q++) {
                double a = 0.0, b = 0.0, c = 0.0;
                for (int i = 0; i < m; i++) {
                    a += A[i * n + p] * A[i * n + p];
                    b += A[i * n + q] * A[i * n + q];
                    c += A[i * n + p] * A[i * n + q];
                }
                if (!(fabs(c) > 1e-15 * sqrt(a * b))) continue;
                done = 0;
                double zeta = (b - a) / (2.0 * c);
                double t = (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
                double cs = 1.0 / sqrt(1.0 + t * t), sn = cs * t;
                for (int i = 0; i < m; i++) {
                    double x = A[i * n + p], y = A[i * n + q];
                    A[i * n + p] = cs * x - sn * y;
                    A[i * n + q] = sn * x + cs * y;
                }
                for (int i = 0; i < n; i++) {
                    double x = V[i * n + p], y = V[i * n + q];
                    V[i * n + p] = cs * x - sn * y;
                    V[i * n + q] = sn * x + cs * y;
                }
            }
    }
    if (!done) return -1;
    for (int k = 0; k < n; k++) {
        double a = 0.0;
        for (int i = 0; i < m; i++) a += A[i * n + k] * A[i * n + k];
        s[k] = sqrt(a);
    }
    for (int k = 0; k < n; k++) { /* selection sort, descending, columns of V along */
        int best = k;
        for (int j = k + 1; j < n; j++)
            if (s[j] > s[best]) best = j;
        if (best == k) continue;
        double t = s[k]; s[k] = s[best]; s[best] = t;
        for (int i = 0; i < n; i++) { t = V[i * n + k]; V[i * n + k] = V[i * n + best]; V[i * n + best] = t; }
    }
    return 0;
}

/* W(u3, u4) = sum C[i][j] u3^i u4^j (8) and the largest |W^T Q_q W| / |W|^2 of the nq quadrics. */
static double ik4_on_quadrics(double u, double v, int d3, int d4, const double *C, int nq, const double *Q, double *w)
{
    double ww = 0.0, worst = 0.0;
    for (int a = 0; a < 8; a++) {
        double s = 0.0;
        for (int i = d3; i >= 0; i--) {
            double t = 0.0;
            for (int l = d4; l >= 0; l--) t = t * v + C[8 * (i * (d4 + 1) + l) + a];
            s = s * u + t;
        }
        w[a] = s;
        ww += s * s;
    }
    for (int q = 0; q < nq; q++) {
        double s = 0.0;
        for (int a = 0; a < 8; a++)
            for (int b = 0; b < 8; b++) s += w[a] * Q[64 * q + 8 * a + b] * w[b];
        if (fabs(s) > worst) worst = fabs(s);
    }
    return worst / (ww > 1e-300 ? ww : 1e-300);
}

/* The Sylvester matrix S (N x N) in u4 of f(u3, .), g(u3, .) (fu, gu: their coefficients at u3). */
static void ik4_sylvester(int F1, int G1, const double *fu, const double *gu, double *S)
{
    int N = F1 + G1;
    for (int k = 0; k < N * N; k++) S[k] = 0.0;
    for (int r = 0; r < G1; r++)
        for (int c = 0; c <= F1; c++) S[r * N + r + c] = fu[c];
    for (int r = 0; r < F1; r++)
        for (int c = 0; c <= G1; c++) S[(G1 + r) * N + r + c] = gu[c];
}

/* p(u, v) and its partial derivatives, p: (P0 + 1) x (P1 + 1) coefficients of u^i v^j. */
static void bivariate(const double *p, int P0, int P1, double u, double v, double *val, double *du, double *dv)
{
    double s = 0.0, su = 0.0, sv = 0.0;
    for (int i = P0; i >= 0; i--) {
        double t = 0.0, tv = 0.0;
        for (int j = P1; j >= 0; j--) { tv = tv * v + t; t = t * v + p[i * (P1 + 1) + j]; }
        su = su * u + s;
        s = s * u + t;
        sv = sv * u + tv;
    }
    *val = s; *du = su; *dv = sv;
}

int apair_ik4_screen(size_t count, const double *u3, int d3, int d4, const double *C, const double *f,
                     int F0, int F1, const double *g, int G0, int G1, int nq, const double *Q,
                     const double *probe, const double *tol, int *status, double *u4, double *W, double *rel,
                     double *two, int *two_ok, double *W2, double *rel2)
{
    int N = F1 + G1;
    if (N < 1 || N > IK4_N) return -1;
    for (size_t j = 0; j < count; j++) {
        double u = u3[j], fu[IK4_DEG + 1], gu[IK4_DEG + 1], S[IK4_N * IK4_N], x[IK4_N];
        for (int c = 0; c <= F1; c++) {
            double s = 0.0;
            for (int i = F0; i >= 0; i--) s = s * u + f[i * (F1 + 1) + c];
            fu[c] = s;
        }
        for (int c = 0; c <= G1; c++) {
            double s = 0.0;
            for (int i = G0; i >= 0; i--) s = s * u + g[i * (G1 + 1) + c];
            gu[c] = s;
        }
        int bad = 0;
        for (int i = 0; i < N; i++) x[i] = probe[i];
        for (int it = 0; it < 2 && !bad; it++) { /* two steps of inverse iteration */
            ik4_sylvester(F1, G1, fu, gu, S);
            bad = rsolve_m(N, S, 1, x);
            double s = 0.0;
            for (int i = 0; i < N; i++) s += x[i] * x[i];
            s = sqrt(s);
            bad |= !(s > 0.0) || !isfinite(s);
            for (int i = 0; i < N && !bad; i++) x[i] /= s;
        }
        double num = 0.0, den = 0.0, v = 0.0;
        for (int i = 0; i + 1 < N && !bad; i++) { num += x[i] * x[i + 1]; den += x[i] * x[i]; }
        v = bad ? 0.0 : num / (den > 1e-300 ? den : 1e-300);
        double dev = 0.0;
        for (int i = 0; i + 1 < N && !bad; i++) dev += (x[i + 1] - v * x[i]) * (x[i + 1] - v * x[i]);
        int vandermonde = !bad && sqrt(dev) <= tol[0];
        u4[j] = v;
        rel[j] = ik4_on_quadrics(u, v, d3, d4, C, nq, Q, W + 8 * j);
        status[j] = rel[j] <= tol[1] ? 0 : !(rel[j] <= tol[2]) ? 1 : 2;
        two_ok[2 * j] = two_ok[2 * j + 1] = 0;
        for (int k = 0; k < 4; k++) two[4 * j + k] = 0.0;
        for (int k = 0; k < 16; k++) W2[16 * j + k] = 0.0;
        rel2[2 * j] = rel2[2 * j + 1] = 0.0;
        if (vandermonde) continue;
        /* a two-dimensional null space: its two roots u4, the eigenvalues of the shift X with
         * N[1:] = N[:-1] X on a null basis N (least squares), each Newton-polished on (f, g) */
        status[j] = 4;
        double A[IK4_N * IK4_N], sv[IK4_N], V[IK4_N * IK4_N];
        ik4_sylvester(F1, G1, fu, gu, A);
        if (N < 3 || jacobi_svd(N, N, A, sv, V)) continue;
        if (!(sv[N - 2] <= 1e-5 * sv[0]) || !(sv[N - 3] > 1e3 * sv[N - 2])) continue;
        double Gm[4] = {0.0, 0.0, 0.0, 0.0}, R[4] = {0.0, 0.0, 0.0, 0.0};
        for (int i = 0; i + 1 < N; i++)
            for (int p = 0; p < 2; p++)
                for (int q = 0; q < 2; q++) {
                    Gm[2 * p + q] += V[i * N + N - 2 + p] * V[i * N + N - 2 + q];
                    R[2 * p + q] += V[i * N + N - 2 + p] * V[(i + 1) * N + N - 2 + q];
                }
        double det = Gm[0] * Gm[3] - Gm[1] * Gm[2];
        if (!(fabs(det) > 0.0)) continue;
        double X[4] = {(Gm[3] * R[0] - Gm[1] * R[2]) / det, (Gm[3] * R[1] - Gm[1] * R[3]) / det,
                       (Gm[0] * R[2] - Gm[2] * R[0]) / det, (Gm[0] * R[3] - Gm[2] * R[1]) / det};
        double res = 0.0;
        for (int i = 0; i + 1 < N; i++)
            for (int q = 0; q < 2; q++) {
                double e = V[i * N + N - 2] * X[q] + V[i * N + N - 1] * X[2 + q] - V[(i + 1) * N + N - 2 + q];
                res += e * e;
            }
        if (!(sqrt(res) <= 1e-4)) continue;
        status[j] = 3;
        double tr = X[0] + X[3], dt = X[0] * X[3] - X[1] * X[2], disc = 0.25 * tr * tr - dt;
        double roots[2], im = disc < 0.0 ? sqrt(-disc) : 0.0;
        roots[0] = 0.5 * tr + (disc >= 0.0 ? sqrt(disc) : 0.0);
        roots[1] = 0.5 * tr - (disc >= 0.0 ? sqrt(disc) : 0.0);
        for (int r = 0; r < 2; r++) {
            double modulus = disc >= 0.0 ? fabs(roots[r]) : sqrt(fabs(dt));
            if (!(im <= 1e-2 * (1.0 + modulus))) continue; /* a complex root is no solution */
            double a = u, b = roots[r];
            for (int step = 0; step < 3; step++) {
                double F, Fu, Fv, G, Gu, Gv;
                bivariate(f, F0, F1, a, b, &F, &Fu, &Fv);
                bivariate(g, G0, G1, a, b, &G, &Gu, &Gv);
                double d = Fu * Gv - Fv * Gu;
                if (d == 0.0) d = INFINITY;
                double da = (F * Gv - Fv * G) / d, db = (Fu * G - F * Gu) / d;
                a -= da;
                b -= db;
            }
            two_ok[2 * j + r] = 1;
            two[4 * j + 2 * r] = a;
            two[4 * j + 2 * r + 1] = b;
            rel2[2 * j + r] = ik4_on_quadrics(a, b, d3, d4, C, nq, Q, W2 + 16 * j + 8 * r);
        }
    }
    return 0;
}

/* max_k |p_k(u)| / sum_j |u|^j max_k |p_k,j| for polynomials p (k x (d + 1), ascending). */
static double relres(int k, int d, const double *p, double u)
{
    double num = 0.0, den = 0.0;
    for (int r = 0; r < k; r++) {
        double s = 0.0;
        for (int j = d; j >= 0; j--) s = s * u + p[r * (d + 1) + j];
        if (fabs(s) > num) num = fabs(s);
    }
    for (int j = 0; j <= d; j++) {
        double big = 0.0;
        for (int r = 0; r < k; r++)
            if (fabs(p[r * (d + 1) + j]) > big) big = fabs(p[r * (d + 1) + j]);
        den += big * pow(fabs(u), j);
    }
    return num / (den > 1e-300 ? den : 1e-300);
}

#define IK4_D1 8 /* the largest degree of the first joint's curve */
#define IK4_PI 3.14159265358979323846

int apair_ik4_left(size_t count, const double *W, int d1, const double *Zmap, int d2, const double *P2,
                   const double *joint, const double *tol, int *status, double *u1, double *u2, int *ok)
{
    static const int outside[4] = {1, 2, 5, 6};
    if (d1 < 1 || d1 > IK4_D1 || d2 < 1 || d2 > IK4_D1) return -1;
    for (size_t j = 0; j < count; j++) {
        double Zc[(IK4_D1 + 1) * 8], big = 0.0, out = 0.0;
        for (int m = 0; m <= d1; m++)
            for (int a = 0; a < 8; a++) {
                double s = 0.0;
                for (int b = 0; b < 8; b++) s += Zmap[64 * m + 8 * a + b] * W[8 * j + b];
                Zc[8 * m + a] = s;
                if (fabs(s) > big) big = fabs(s);
            }
        for (int m = 0; m <= d1; m++)
            for (int k = 0; k < 4; k++)
                if (fabs(Zc[8 * m + outside[k]]) > out) out = fabs(Zc[8 * m + outside[k]]);
        status[j] = 1;
        u1[j] = u2[2 * j] = u2[2 * j + 1] = 0.0;
        ok[2 * j] = ok[2 * j + 1] = 0;
        if (out <= 1e-10 * big) continue; /* joints 1 and 2 on one axis: the caller's case */
        /* the outside components' polynomials times u^0 .. u^(d1 - 1): (4 d1) x (2 d1), one null vector */
        int rows = 4 * d1, cols = 2 * d1;
        double M[4 * IK4_D1 * 2 * IK4_D1], A[4 * IK4_D1 * 2 * IK4_D1], s[2 * IK4_D1], V[4 * IK4_D1 * IK4_D1];
        for (int i = 0; i < rows * cols; i++) M[i] = 0.0;
        for (int sh = 0; sh < d1; sh++)
            for (int k = 0; k < 4; k++)
                for (int m = 0; m <= d1; m++) M[(4 * sh + k) * cols + sh + m] = Zc[8 * m + outside[k]];
        memcpy(A, M, sizeof(double) * rows * cols);
        if (jacobi_svd(rows, cols, A, s, V)) continue;
        /* a common root with relative residual r puts s[cols - 1] <= r sqrt(rows cols) s[0] */
        if (s[cols - 1] > tol[3] * s[0]) { status[j] = 2; continue; }
        double num = 0.0, den = 0.0, dev = 0.0;
        for (int i = 0; i + 1 < cols; i++) {
            num += V[i * cols + cols - 1] * V[(i + 1) * cols + cols - 1];
            den += V[i * cols + cols - 1] * V[i * cols + cols - 1];
        }
        double u = num / (den > 1e-300 ? den : 1e-300);
        for (int i = 0; i + 1 < cols; i++) {
            double e = V[(i + 1) * cols + cols - 1] - u * V[i * cols + cols - 1];
            dev += e * e;
        }
        if (!(s[cols - 2] > tol[1] * s[0]) || !(sqrt(dev) <= tol[2]) || !(relres(rows, cols - 1, M, u) <= tol[0])) continue;
        /* Z(u1) and joint 2's parameters of its rotation angle, each tested on the minors of P2 with Z */
        double Z[8];
        for (int a = 0; a < 8; a++) {
            double t = 0.0;
            for (int m = d1; m >= 0; m--) t = t * u + Zc[8 * m + a];
            Z[a] = t;
        }
        double theta = (2.0 * atan2(Z[3], Z[0]) - joint[2]) / joint[3];
        int revolute = joint[0] != 0.0, found = 0;
        for (int c = 0; c < (revolute ? 1 : 2); c++) {
            double v = revolute ? tan((theta - joint[1]) / 2.0) : tan((theta + 2.0 * IK4_PI * c - joint[1]) / 4.0);
            double minors[28 * (IK4_D1 + 1)];
            for (int a = 0, r = 0; a < 8; a++)
                for (int b = a + 1; b < 8; b++, r++)
                    for (int m = 0; m <= d2; m++) minors[r * (d2 + 1) + m] = P2[8 * m + a] * Z[b] - P2[8 * m + b] * Z[a];
            u2[2 * j + c] = v;
            ok[2 * j + c] = relres(28, d2, minors, v) <= tol[0];
            found |= ok[2 * j + c];
        }
        u1[j] = u;
        status[j] = found ? 0 : 1;
    }
    return 0;
}

/*
 * A copy of src/csrc/apair_ik_closed.h (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik_closed.h. Content hash: 8554d27ad526bdbf
 */
/*
 * Private to the closed-form solvers of six-joint chains (apair_ik_wrist.c, apair_ik_parallel.c,
 * apair_ik_three_parallel.c, with the A-pair arms' forms in the first two; their Python twins share
 * apair.ik.closed): the real roots of their univariate polynomials, the DH
 * joint transform, fk with the pose error, the Gauss-Newton polish, and the merged, sorted set of
 * verified solutions. Static functions: each solver's file gets its own copy to inline.
 */
#ifndef APAIR_IK_CLOSED_H
#define APAIR_IK_CLOSED_H

#include "apair_ik_internal.h"

#define CLOSED_FLAT 1e-9      /* a length (relative to the scale), a sine or a coefficient this small is zero */
#define CLOSED_SINGULAR 1e-7  /* an angle this close to 0 or pi (at a double root) is taken as there */
#define CLOSED_DOUBLE 1e-14   /* a squared sine within this (relative) of 0: one root, not two */
#define CLOSED_TANGENT 1e-8  /* a local extremum of the polynomial this close to 0 (relative) is a root */
#define CLOSED_SPLIT 1e-6    /* two real roots of a quadratic this far apart (relative) are two, not a split double root */
#define CLOSED_INV_MAX 1024
#define CLOSED_DEGREE 12 /* the highest degree closed_real_roots takes (the A-pair UR arm's polynomial) */
#define CLOSED_ROOTS 64 /* room for closed_real_roots' answer: 3 for d = 2, at most 2 n(d - 1) + 1 above (15 for
                         * d = 4); above that the candidates (a root per sign change, a near-zero critical point
                         * each) stay far below it unless roots cluster, and any beyond it are dropped */

GAUSS_SOLVE(closed_solve6, double, fabs)


/* fk6 and jacobian6 with their invariants for one design: R-pairs, and sinusoidal A-pairs of
 * amplitude amp[i] (0 for an R-pair) */
typedef struct {
    const apair_kernel *fk, *jac;
    double inv_fk[CLOSED_INV_MAX], inv_jac[CLOSED_INV_MAX];
    double turning[6], amp[6];
} closed_fk;

/* 0, or -1 where the kernels are missing or too big for the buffers */
static inline int closed_fk_init(closed_fk *k, const double *dh)
{
    k->fk = apair_find_kernel("fk6");
    k->jac = apair_find_kernel("jacobian6");
    if (!k->fk || !k->jac || k->fk->n_invariants > CLOSED_INV_MAX || k->jac->n_invariants > CLOSED_INV_MAX) return -1;
    for (int i = 0; i < 6; i++) { k->turning[i] = 1.0; k->amp[i] = 0.0; }
    const double *in[3] = {NULL, dh, k->turning};
    if (k->fk->n_invariants) k->fk->invariants(in, k->inv_fk);
    if (k->jac->n_invariants) k->jac->invariants(in, k->inv_jac);
    return 0;
}

static inline double closed_horner(int d, const double *c, double x)
{
    double s = c[d];
    for (int k = d - 1; k >= 0; k--) s = s * x + c[k];
    return s;
}

static inline double closed_magnitude(int d, const double *c, double x)
{
    double s = 0.0, ax = fabs(x), p = 1.0;
    for (int k = 0; k <= d; k++, p *= ax) s += fabs(c[k]) * p;
    return s;
}

/* The real roots of sum c_k x^k (degree d <= CLOSED_DEGREE, c[d] != 0, coefficients of size about
 * 1): a root in each interval between the real roots of the derivative where the sign changes, and
 * each critical point within CLOSED_TANGENT of zero (a double root, or two roots too close to
 * separate) unless roots were bracketed on both sides of it, each more than CLOSED_SPLIT away:
 * candidates, some repeated, at most 3 for d = 2 and 15 for d = 4, CLOSED_ROOTS in all. */
static inline int closed_real_roots(int d, const double *c, double *roots)
{
    if (d <= 0) return 0;
    if (d == 1) { roots[0] = -c[0] / c[1]; return 1; }
    if (d == 2) { /* the stable formula; a discriminant within CLOSED_TANGENT of 0: the double root too (the
                   * critical point, exact where the two roots are sqrt(eps) off it, or complex by rounding),
                   * but not between two real roots CLOSED_SPLIT apart: two solutions, and the point between
                   * them nearly verifies (to 3e-11 on a PUMA's pose with roots 1.7e-5 apart) */
        double disc = c[1] * c[1] - 4 * c[2] * c[0], near = fabs(disc) <= CLOSED_TANGENT * (c[1] * c[1] + fabs(4 * c[2] * c[0]) + c[2] * c[2]);
        double mid = -c[1] / (2 * c[2]);
        int n = 0;
        if (disc >= 0) {
            double qq = -0.5 * (c[1] + copysign(sqrt(disc), c[1]));
            double r1 = qq / c[2], r2 = qq != 0.0 ? c[0] / qq : -r1;
            roots[n++] = fmin(r1, r2);
            roots[n++] = fmax(r1, r2);
            if (fabs(r1 - r2) > CLOSED_SPLIT * (1.0 + fabs(mid))) near = 0;
        }
        if (near) roots[n++] = mid;
        return n;
    }
    double dc[CLOSED_DEGREE], crit[CLOSED_ROOTS];
    for (int k = 1; k <= d; k++) dc[k - 1] = k * c[k];
    int nc = closed_real_roots(d - 1, dc, crit);
    /* every root within the smaller of Cauchy's and Fujiwara's bounds (Fujiwara's is far tighter where
     * the leading coefficient is small: Newton's method from a far end gains only a factor 1 - 1/d a step) */
    double cauchy = 0.0, fujiwara = 0.0;
    for (int k = 0; k < d; k++) {
        cauchy = fmax(cauchy, fabs(c[k] / c[d]));
        fujiwara = fmax(fujiwara, pow(fabs(c[k] / c[d]) * (k == 0 ? 0.5 : 1.0), 1.0 / (d - k)));
    }
    double bound = fmin(cauchy + 1.0, 2.0 * fujiwara);
    double ends[CLOSED_ROOTS + 2];
    int ne = 0;
    ends[ne++] = -bound;
    for (int k = 0; k < nc; k++) ends[ne++] = fmin(fmax(crit[k], -bound), bound);
    ends[ne++] = bound;
    int n = 0;
    double before = NAN; /* the root bracketed in the interval before this one, if any */
    for (int k = 0; k + 1 < ne; k++) {
        double lo = ends[k], hi = ends[k + 1], flo = closed_horner(d, c, lo), fhi = closed_horner(d, c, hi);
        if (n >= CLOSED_ROOTS - 1) break;
        int at_crit = -1;
        if (k > 0 && fabs(flo) <= CLOSED_TANGENT * fmax(1.0, closed_magnitude(d, c, lo))) { at_crit = n; roots[n++] = lo; } /* at a critical point */
        double prev = before;
        before = NAN;
        if (flo == 0.0) continue;
        if ((flo < 0) == (fhi < 0)) continue;
        /* Laguerre's method from the secant point (one step lands near a root from afar, where Newton's
         * gains only a factor 1 - 1/d), else Newton's, kept inside the bracket (a bisection step, on a log
         * scale across magnitudes, where both would leave it), to 1e-14 relative: the candidates are
         * polished on fk afterwards */
        double x = lo - flo * (hi - lo) / (fhi - flo);
        if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
        for (int it = 0; it < 100; it++) {
            double f = c[d], df = 0.0, ddf = 0.0;
            for (int k = d - 1; k >= 0; k--) {
                ddf = ddf * x + df;
                df = df * x + f;
                f = f * x + c[k];
            }
            if (f == 0.0) break;
            if ((f < 0) == (flo < 0)) lo = x; else hi = x;
            double G = df / f, H = G * G - 2 * ddf / f, disc = (d - 1) * (d * H - G * G), next = x - f / df;
            if (disc >= 0) {
                double den = G + copysign(sqrt(disc), G), leap = den != 0.0 ? x - d / den : next;
                if (leap > lo && leap < hi) next = leap;
            }
            if (!(next > lo && next < hi))
                next = lo > 0 && hi > 4 * lo ? sqrt(lo * hi) : hi < 0 && lo < 4 * hi ? -sqrt(lo * hi) : 0.5 * (lo + hi);
            if (fabs(next - x) <= 1e-14 * fmax(1.0, fabs(x)) || hi - lo <= 1e-14 * fmax(1.0, fabs(lo))) { x = next; break; }
            x = next;
        }
        roots[n++] = x;
        before = x;
        /* a critical point between two real roots, each more than CLOSED_SPLIT from it, is not a root
         * (p changes sign on both sides and p(lo) != 0): two solutions, and the point between them nearly
         * verifies, as the quadratic's above; within CLOSED_SPLIT the two are a split double root */
        double at = ends[k], split = CLOSED_SPLIT * (1.0 + fabs(at)); /* (lo moved with the bracket) */
        if (at_crit >= 0 && at - prev > split && x - at > split) { roots[at_crit] = x; n = at_crit + 1; }
    }
    return n;
}

/* The angles psi = 2 atan t of the real roots t of sum c_k t^k (degree deg <= CLOSED_DEGREE; psi = pi
 * where the degree drops: the root at t = infinity) into psi (room for CLOSED_ROOTS + 1): their count, or -1
 * where every coefficient is below CLOSED_FLAT ref, the size of its terms (psi then moves nothing
 * the polynomial sees: not separated). */
static inline int closed_half_angles(int deg, const double *c, double ref, double *psi)
{
    double size = 0.0, cn[CLOSED_DEGREE + 1], roots[CLOSED_ROOTS];
    for (int k = 0; k <= deg; k++) size = fmax(size, fabs(c[k]));
    if (!(size > CLOSED_FLAT * ref)) return -1;
    for (int k = 0; k <= deg; k++) cn[k] = c[k] / size;
    int top = deg;
    while (top > 0 && fabs(cn[top]) <= CLOSED_FLAT) top--;
    int n = closed_real_roots(top, cn, roots);
    for (int k = 0; k < n; k++) psi[k] = 2 * atan(roots[k]);
    if (top < deg) psi[n++] = CLOSED_PI;
    return n;
}

/* fk and (if J) the Jacobian (6 x 6) at joint angles q; the pose error e as apair.ik.poses:
 * [(t_T - t) / scale; rotation]; returns the largest entry of |fk - T|, translations / scale. */
static inline double closed_evaluate(const closed_fk *w, const double *dh, double scale, const double *q, const double *Tt,
                       double *e, double *J)
{
    double law[30], T[16];
    for (int i = 0; i < 6; i++) { /* a sinusoidal pair's d = h C, d' = -h S / 2, d'' = -h C / 4 (C, S: of q / 2) */
        double C = cos(0.5 * q[i]), S = sin(0.5 * q[i]), h = w->amp[i];
        law[5 * i] = C;
        law[5 * i + 1] = S;
        law[5 * i + 2] = h != 0.0 ? h * C : 0.0;
        law[5 * i + 3] = h != 0.0 ? -0.5 * h * S : 0.0;
        law[5 * i + 4] = h != 0.0 ? -0.25 * h * C : 0.0;
    }
    const double *in[3] = {law, dh, w->turning};
    double *outT[1] = {T};
    if (w->fk->n_invariants) w->fk->core(w->inv_fk, in, outT); else w->fk->eval(in, outT);
    if (J) {
        double *outJ[1] = {J};
        if (w->jac->n_invariants) w->jac->core(w->inv_jac, in, outJ); else w->jac->eval(in, outJ);
    }
    double worst = 0.0;
    for (int k = 0; k < 12; k++) {
        double d = fabs(T[k] - Tt[k]) / (k % 4 == 3 ? scale : 1.0);
        if (d > worst) worst = d;
    }
    for (int r = 0; r < 3; r++) e[r] = (Tt[4 * r + 3] - T[4 * r + 3]) / scale;
    double S[9];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) S[3 * r + k] = Tt[4 * r] * T[4 * k] + Tt[4 * r + 1] * T[4 * k + 1] + Tt[4 * r + 2] * T[4 * k + 2];
    e[3] = 0.5 * (S[7] - S[5]);
    e[4] = 0.5 * (S[2] - S[6]);
    e[5] = 0.5 * (S[3] - S[1]);
    return isfinite(worst) ? worst : INFINITY;
}

/* Up to two Gauss-Newton steps (as apair.ik.poses.refine); the error of the result. */
static inline double closed_polish(const closed_fk *w, const double *dh, double scale, const double *Tt, double tol, double *q)
{
    double e[6], J[36];
    double err = closed_evaluate(w, dh, scale, q, Tt, e, NULL);
    if (err > 1e-3 * tol) closed_evaluate(w, dh, scale, q, Tt, e, J); /* the Jacobian only where a step is taken */
    for (int step = 0; step < 2 && err > 1e-3 * tol; step++) {
        double A[36], x[6], trial[6], e2[6], J2[36];
        for (int r = 0; r < 6; r++)
            for (int k = 0; k < 6; k++) A[6 * r + k] = J[6 * r + k] / (r < 3 ? scale : 1.0);
        memcpy(x, e, sizeof x);
        if (closed_solve6(6, A, 1, x)) break;
        for (int i = 0; i < 6; i++) trial[i] = q[i] + x[i];
        double err2 = closed_evaluate(w, dh, scale, trial, Tt, e2, J2);
        if (!(err2 < err)) break;
        memcpy(q, trial, sizeof trial);
        memcpy(e, e2, sizeof e);
        memcpy(J, J2, sizeof J);
        err = err2;
    }
    return err;
}

static inline int closed_same_angles(const double *a, const double *b)
{
    for (int i = 0; i < 6; i++)
        if (fabs(closed_wrap(a[i] - b[i])) >= 1e-6) return 0;
    return 1;
}

/* x (verified, error err) into the solutions of one pose: a duplicate of one kept (closed_same_angles)
 * replaces it where its error is smaller; at most `most` kept */
static inline void closed_keep_at_most(double *q, double *error, int *found, const double *x, double err, int most)
{
    for (int k = 0; k < *found; k++)
        if (closed_same_angles(q + 6 * k, x)) {
            if (err < error[k]) { memcpy(q + 6 * k, x, 6 * sizeof *x); error[k] = err; }
            return;
        }
    if (*found < most) {
        memcpy(q + 6 * *found, x, 6 * sizeof *x);
        error[(*found)++] = err;
    }
}

static inline void closed_keep(double *q, double *error, int *found, const double *x, double err) /* at most CLOSED_MAX */
{
    closed_keep_at_most(q, error, found, x, err, CLOSED_MAX);
}

/* The A-pair arms' closed forms (apair_ik_parallel.c, apair_ik_wrist.c): an A-pair's angle has period
 * 4 pi (its slide changes sign at theta + 2 pi), and at a singular pose the roots come sqrt(eps) apart
 * and verify as a cluster around the exact solution. */
#define CLOSED_MULTIPLE 1e-4 /* [rad] verified solutions this close are one (a multiple root's cluster) */

static inline double closed_wrap4(double x) /* into (-2 pi, 2 pi], an A-pair's angle */
{
    return x - 4 * CLOSED_PI * ceil((x - 2 * CLOSED_PI) / (4 * CLOSED_PI));
}

/* whether every joint of a and b is within `within` (an A-pair's, amp[i] != 0, modulo 4 pi, the others modulo 2 pi) */
static inline int closed_apair_near(const double *amp, const double *a, const double *b, double within)
{
    for (int i = 0; i < 6; i++) {
        double d = amp[i] != 0.0 ? closed_wrap4(a[i] - b[i]) : closed_wrap(a[i] - b[i]);
        if (!(fabs(d) < within)) return 0;
    }
    return 1;
}

/* x (verified, error err) into the solutions of one pose: one within CLOSED_MULTIPLE of a kept one
 * (a copy, or a multiple root's cluster) replaces it where its error is smaller; at most
 * CLOSED_APAIR_MAX kept */
static inline void closed_apair_keep(const double *amp, double *q, double *error, int *found, const double *x, double err)
{
    for (int k = 0; k < *found; k++)
        if (closed_apair_near(amp, q + 6 * k, x, CLOSED_MULTIPLE)) {
            if (err < error[k]) { memcpy(q + 6 * k, x, 6 * sizeof *x); error[k] = err; }
            return;
        }
    if (*found < CLOSED_APAIR_MAX) {
        memcpy(q + 6 * *found, x, 6 * sizeof *x);
        error[(*found)++] = err;
    }
}

#endif

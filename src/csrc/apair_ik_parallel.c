/*
 * The closed-form inverse kinematics of six-joint R-chains with axes 2, 3 and 4 parallel (UR arms;
 * apair.ik.parallel, where the steps are explained): the derived kernel ik_parallel_position6
 * (derivations/chain_ik_parallel.py) gives L_1(psi_1) = P cos psi_5, L_2(psi_1) = Q sin psi_5 and
 * the polynomial in t = tan(psi_1/2) whose real roots give psi_1; psi_5, psi_6, the elbow's psi_3,
 * psi_2 and psi_4 follow in closed form, and each candidate gets up to two Gauss-Newton steps on
 * fk6 and jacobian6 and is kept where fk reproduces the pose to tol (apair_ik_closed.h, shared with
 * apair_ik_wrist.c). The same steps serve a UR arm with a sinusoidal A-pair at joint 3 (below, after
 * the R-arm's). Hand-written C: the C backend of codegen copies it into generated/c, the
 * library it belongs to. Declared in apair.h (template: codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_closed.h"

typedef struct {
    closed_fk k;
    int which; /* 0: the quartic; 1: L_2's quadratic (Q = 0, a_5 = 0); 2: L_1's (P = 0, axes 5 and 6 parallel) */
    double dh[24], scale, eps, P, Q, ca[6], sa[6], phi[6], o3[3];
    double inv_pos[CLOSED_INV_MAX];
} parallel_design;

/* psi_5 for (psi_1's) l1 = L_1, l2 = L_2; z1, z5: axes 2 and 6 in the base frame */
static int psi5_of(const parallel_design *p, double l1, double l2, const double *z1, const double *z5, double *out)
{
    if (p->which == 0) {
        out[0] = atan2(l2 / p->Q, l1 / p->P);
        return 1;
    }
    double base;
    if (p->which == 1) { /* cos psi_5 = L_1/P; |sin psi_5| from |z1 x z5|^2 = w_x^2 + w_y^2 (exact near psi_5 = 0) */
        double c5 = l1 / p->P;
        if (!(fabs(c5) <= 1 + 1e-6)) return 0;
        double wy = p->sa[3] * fmin(1.0, fmax(-1.0, c5)) * p->ca[4] + p->ca[3] * p->sa[4];
        double x = z1[1] * z5[2] - z1[2] * z5[1], y = z1[2] * z5[0] - z1[0] * z5[2], z = z1[0] * z5[1] - z1[1] * z5[0];
        double s5 = sqrt(fmax(0.0, x * x + y * y + z * z - wy * wy)) / fabs(p->sa[3]);
        base = atan2(s5, c5);
    } else { /* sin psi_5 = L_2/Q: psi_5 and pi - psi_5 */
        double s5 = l2 / p->Q;
        if (!(fabs(s5) <= 1 + 1e-6)) return 0;
        base = asin(fmin(1.0, fmax(-1.0, s5)));
        if (fabs(fabs(base) - CLOSED_PI / 2) <= CLOSED_SINGULAR) { out[0] = copysign(CLOSED_PI / 2, base); return 1; }
        out[0] = base;
        out[1] = CLOSED_PI - base;
        return 2;
    }
    if (base <= CLOSED_SINGULAR) { out[0] = 0.0; return 1; }
    if (base >= CLOSED_PI - CLOSED_SINGULAR) { out[0] = CLOSED_PI; return 1; }
    out[0] = base;
    out[1] = -base;
    return 2;
}

/* N = A_2 A_3 A_4 (3 x 4) and frame 3's origin's (x, y) in frame 1, for psi_1, psi_5, psi_6 */
static void frame3(const parallel_design *p, const double *dh, const double *Tt, double psi1, double psi5, double psi6,
                   double *N, double *O3)
{
    double A1[12], A5[12], A6[12], I1[12], I5[12], I6[12];
    double T34[12] = {Tt[0], Tt[1], Tt[2], Tt[3], Tt[4], Tt[5], Tt[6], Tt[7], Tt[8], Tt[9], Tt[10], Tt[11]};
    closed_dh4(dh[0], p->ca[0], p->sa[0], dh[2], psi1, A1);
    closed_dh4(dh[16], p->ca[4], p->sa[4], dh[18], psi5, A5);
    closed_dh4(dh[20], p->ca[5], p->sa[5], dh[22], psi6, A6);
    closed_inv34(A1, I1);
    closed_inv34(A5, I5);
    closed_inv34(A6, I6);
    closed_mul34(I1, T34, N);
    closed_mul34(N, I6, N);
    closed_mul34(N, I5, N);
    for (int r = 0; r < 2; r++) O3[r] = N[4 * r + 3] - (N[4 * r] * p->o3[0] + N[4 * r + 1] * p->o3[1] + N[4 * r + 2] * p->o3[2]);
}

/* rho^2 = A + B cos psi_6 + C sin psi_6: frame 3's distance from axis 2 as psi_6 turns */
static void circle(const parallel_design *p, const double *dh, const double *Tt, double psi1, double psi5, double *A,
                   double *B, double *C)
{
    double N[12], O3[2], r[3];
    for (int k = 0; k < 3; k++) {
        frame3(p, dh, Tt, psi1, psi5, k * CLOSED_PI / 2, N, O3);
        r[k] = O3[0] * O3[0] + O3[1] * O3[1];
    }
    *A = 0.5 * (r[0] + r[2]);
    *B = 0.5 * (r[0] - r[2]);
    *C = r[1] - *A;
}

/* Where axis 6 is parallel to axes 2-4, psi_6 is free: frame 3's origin then runs on a circle as
 * psi_6 turns, rho^2 = A + B cos psi_6 + C sin psi_6; the member taken has the elbow at cos psi_3 = 0
 * (rho^2 = a_2^2 + a_3^2, the middle of its range) where the circle reaches it, else the nearest. */
static double free_psi6(const parallel_design *p, const double *dh, const double *Tt, double psi1, double psi5)
{
    double A, B, C;
    circle(p, dh, Tt, psi1, psi5, &A, &B, &C);
    double K = hypot(B, C);
    double a2 = dh[4], a3 = dh[8], scale2 = a2 * a2 + a3 * a3;
    if (!(K > CLOSED_FLAT * scale2)) return 0.0;
    return atan2(C, B) + acos(fmin(1.0, fmax(-1.0, (scale2 - A) / K)));
}

/* psi_2, psi_3, psi_4 of the planar problem left by psi_1, psi_5, psi_6 (per elbow, at most 2; one,
 * the stretched or folded elbow, where sin^2 psi_3 <= stretched): candidates x = psi - phi */
static int inner(const parallel_design *p, const double *dh, double scale, const double *Tt, double psi1, double psi5,
                 double psi6, double *x, int *flags, double stretched)
{
    double N[12], O3[2];
    frame3(p, dh, Tt, psi1, psi5, psi6, N, O3); /* N = A_2 A_3 A_4 */
    double a2 = dh[4], a3 = dh[8], rho2 = O3[0] * O3[0] + O3[1] * O3[1];
    double c3 = (rho2 - a2 * a2 - a3 * a3) / (2 * a2 * a3);
    if (!(fabs(c3) <= 1 + 1e-6)) return 0;
    double rest = 1 - c3 * c3, s3 = rest <= stretched ? 0.0 : sqrt(rest);
    int n = 0;
    for (int s = 0; s < (s3 > 0 ? 2 : 1); s++) {
        double psi3 = atan2(s ? -s3 : s3, c3), psi2;
        if (rho2 <= (CLOSED_FLAT * scale) * (CLOSED_FLAT * scale)) { *flags |= 2; psi2 = 0.0; }
        else psi2 = atan2(O3[1], O3[0]) - atan2(p->ca[1] * a3 * sin(psi3), a2 + a3 * cos(psi3));
        double A2[12], A3[12];
        closed_dh4(a2, p->ca[1], p->sa[1], dh[6], psi2, A2);
        closed_dh4(a3, p->ca[2], p->sa[2], dh[10], psi3, A3);
        closed_mul34(A2, A3, A2);
        /* M = R_3^T N's rotation = Rz(psi_4) Rx(alpha_4): its first column */
        double m00 = A2[0] * N[0] + A2[4] * N[4] + A2[8] * N[8], m10 = A2[1] * N[0] + A2[5] * N[4] + A2[9] * N[8];
        double psi[6] = {psi1, psi2, psi3, atan2(m10, m00), psi5, psi6};
        for (int i = 0; i < 6; i++) x[6 * n + i] = closed_wrap(psi[i] - p->phi[i]);
        n++;
    }
    return n;
}

/* the prepared design lives in apair_ik_closed's storage */
typedef char parallel_design_fits[sizeof(parallel_design) <= sizeof(((apair_ik_closed *)0)->design) ? 1 : -1];

int apair_ik_parallel_prepare(void *design, const double *dh, double scale)
{
    parallel_design *p = (parallel_design *)design;
    if (closed_fk_init(&p->k, dh) || !(scale > 0) || APAIR_IK_PARALLEL_POSITION6_INVARIANTS > CLOSED_INV_MAX) return -1;
    memcpy(p->dh, dh, sizeof p->dh);
    p->scale = scale;
    apair_ik_parallel_position6_invariants(dh, p->inv_pos);
    for (int i = 0; i < 6; i++) { p->ca[i] = cos(dh[4 * i + 1]); p->sa[i] = sin(dh[4 * i + 1]); p->phi[i] = dh[4 * i + 3]; }
    p->eps = p->ca[1] * p->ca[2];
    p->P = -p->eps * p->sa[3] * p->sa[4];
    p->Q = p->eps * p->sa[3] * dh[16];
    int p0 = fabs(p->P) <= CLOSED_FLAT, q0 = fabs(p->Q) <= CLOSED_FLAT * scale;
    /* axes 2, 3, 4 not parallel, or axes 5 and 6 one line: not this closed form */
    if (fabs(p->sa[1]) > CLOSED_FLAT || fabs(p->sa[2]) > CLOSED_FLAT || (p0 && q0)) return -1;
    p->which = q0 ? 1 : p0 ? 2 : 0;
    p->o3[0] = dh[12];
    p->o3[1] = dh[14] * p->sa[3];
    p->o3[2] = dh[14] * p->ca[3];
    return 0;
}

/* The first step at pose T: L (L_1, L_2 in (1, cos psi_1, sin psi_1)) and psi_1 at the real roots of the
 * design's polynomial (room for CLOSED_ROOTS + 1); their count, or -1 where it vanishes identically */
static int first_step(const parallel_design *p, const double *Tt, double *L, double *psi1s)
{
    double PQ[2], quartic[5], qa[3], qb[3];
    apair_ik_parallel_position6_core(p->inv_pos, p->dh, Tt, L, PQ, quartic, qa, qb);
    const double *c = p->which == 0 ? quartic : p->which == 1 ? qb : qa;
    double big = p->scale + sqrt(Tt[3] * Tt[3] + Tt[7] * Tt[7] + Tt[11] * Tt[11]);
    double ref = p->which == 0 ? (big * p->P) * (big * p->P) + p->Q * p->Q : p->which == 1 ? big : 1.0;
    return closed_half_angles(p->which == 0 ? 4 : 2, c, ref, psi1s);
}

void apair_ik_parallel_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej, int *found,
                              int *candidates, int *flags)
{
    const parallel_design *p = (const parallel_design *)design;
    const double *dh = p->dh, eps = p->eps;
    double scale = p->scale, L[6], psi1s[CLOSED_ROOTS + 1];
    *found = *candidates = *flags = 0;
    int n1 = first_step(p, Tt, L, psi1s);
    if (n1 < 0) { *flags = -1; return; } /* the polynomial vanishes: not separated */
    double z5[3], ca6 = p->ca[5], sa6 = p->sa[5];
    for (int r = 0; r < 3; r++) z5[r] = Tt[4 * r + 1] * sa6 + Tt[4 * r + 2] * ca6;
    for (int k1 = 0; k1 < n1; k1++) {
        double c1 = cos(psi1s[k1]), s1 = sin(psi1s[k1]);
        double l1 = L[0] + L[1] * c1 + L[2] * s1, l2 = L[3] + L[4] * c1 + L[5] * s1;
        double z1[3] = {p->sa[0] * s1, -p->sa[0] * c1, p->ca[0]}, psi5s[2];
        int n5 = psi5_of(p, l1, l2, z1, z5, psi5s);
        /* v = eps z1^T R_6 Rx(alpha_6)^T: what w Rz(psi_6) must be (w: the third row of Rz(psi_5) Rx(alpha_5)) */
        double u[3];
        for (int k = 0; k < 3; k++) u[k] = z1[0] * Tt[k] + z1[1] * Tt[4 + k] + z1[2] * Tt[8 + k];
        double vx = eps * u[0], vy = eps * (u[1] * ca6 - u[2] * sa6);
        for (int k5 = 0; k5 < n5; k5++) {
            double s5 = sin(psi5s[k5]), c5 = cos(psi5s[k5]);
            double wx = p->sa[3] * s5, wy = p->sa[3] * c5 * p->ca[4] + p->ca[3] * p->sa[4];
            int singular = hypot(wx, wy) <= CLOSED_SINGULAR; /* axis 6 parallel to axes 2-4: psi_6 free */
            double psi6 = singular ? free_psi6(p, dh, Tt, psi1s[k1], psi5s[k5])
                                   : atan2(wy * vx - wx * vy, wx * vx + wy * vy), x[12];
            int nx = inner(p, dh, scale, Tt, psi1s[k1], psi5s[k5], psi6, x, flags, 4 * CLOSED_DOUBLE);
            for (int k = 0; k < nx; k++) {
                (*candidates)++;
                double err = closed_polish(&p->k, dh, scale, Tt, tol, x + 6 * k);
                if (!(err <= tol)) continue;
                for (int i = 0; i < 6; i++) x[6 * k + i] = closed_wrap(x[6 * k + i]);
                closed_keep(qj, ej, found, x + 6 * k, err);
                if (singular) *flags |= 1;
            }
        }
    }
    closed_sort(qj, ej, *found);
}

int apair_ik_parallel(const double *dh, double scale, size_t count, const double *target, ptrdiff_t target_stride,
                      double tol, double *q, double *error, int *found, int *candidates, int *flags)
{
    apair_ik_closed solver;
    if (apair_ik_closed_init(&solver, APAIR_IK_PARALLEL, dh, scale)) return -1;
    return apair_ik_closed_solve(&solver, count, target, target_stride, tol, q, error, found, candidates, flags);
}

/* ---- A UR arm with a sinusoidal A-pair at joint 3 (apair.ik.parallel_apair, where the steps are
 * explained): the derived kernel ik_parallel_apair_position6 (derivations/chain_ik_parallel_apair.py)
 * gives L_1, L_2, G and H in t = tan(psi_1/2) and the polynomial of degree 12 whose real roots give
 * psi_1 (a quartic, G = 0, where c_5 = 0); psi_5 = atan2(H/G, L_1/P), then psi_6, the elbows, psi_2
 * and psi_4 as on the R-arm above; theta_3 is the angle in (-2 pi, 2 pi] whose slide h cos(theta_3/2)
 * has the sign of cos alpha_2 L_2, with its twin where it is near +-pi. */

typedef struct {
    parallel_design p; /* the R-arm's steps; its inv_pos holds ik_parallel_apair_position6's invariants */
    double law[2], h, cphi3;
    int quartic; /* c_5 = 0: H = 0, and G = 0 is a quartic */
} apair_design;

/* the prepared design lives in apair_ik_closed's storage */
typedef char apair_design_fits[sizeof(apair_design) <= sizeof(((apair_ik_closed *)0)->design) ? 1 : -1];

/* the candidates x (n x 6, from inner) with theta_3's representative, and their twins (theta_3 -> -theta_3)
 * where theta_3 is near +-pi (d_3 = 0: both give the pose) appended: their count */
static int apair_angles(const apair_design *d, double *x, int n, double l2)
{
    double d3 = d->p.ca[1] * l2;
    for (int k = 0; k < n; k++) {
        double t3 = closed_wrap(x[6 * k + 2]);
        if (cos(0.5 * t3) * d3 < 0) t3 -= copysign(2 * CLOSED_PI, t3);
        x[6 * k + 2] = t3;
    }
    int m = n;
    for (int k = 0; k < n; k++)
        if (fabs(fabs(x[6 * k + 2]) - CLOSED_PI) <= 1e-4) {
            memcpy(x + 6 * m, x + 6 * k, 6 * sizeof *x);
            x[6 * m + 2] = -x[6 * k + 2];
            m++;
        }
    return m;
}

/* the smallest pose error among n candidates */
static double apair_best(const apair_design *d, const double *Tt, const double *x, int n)
{
    double e[6], best = INFINITY;
    for (int k = 0; k < n; k++) best = fmin(best, closed_evaluate(&d->p.k, d->p.dh, d->p.scale, x + 6 * k, Tt, e, NULL));
    return best;
}

/* The candidates of one (psi_1, psi_5, psi_6): the two elbows, or the stretched (folded) one where that
 * reproduces the pose better (near theta_3 = 0 the slide's top and the elbow's stretch meet: psi_1 is
 * a near-double root, and the elbows' sin psi_3 = +-1e-6 from cos psi_3's error would be two spurious
 * solutions), each polished and kept where it verifies; `continuum`: flag 1 where one does. */
static void apair_elbows(const apair_design *d, const double *Tt, double tol, double l2, double psi1, double psi5,
                         double psi6, int continuum, double *qj, double *ej, int *found, int *candidates, int *flags)
{
    const parallel_design *p = &d->p;
    double x[24], y[24];
    int nx = inner(p, p->dh, p->scale, Tt, psi1, psi5, psi6, x, flags, 4 * CLOSED_DOUBLE);
    int stretched = nx == 2 && fabs(sin(x[2] + p->phi[2])) <= 1e-4;
    nx = apair_angles(d, x, nx, l2);
    if (stretched) {
        int ny = apair_angles(d, y, inner(p, p->dh, p->scale, Tt, psi1, psi5, psi6, y, flags, 1.0), l2);
        if (apair_best(d, Tt, y, ny) <= apair_best(d, Tt, x, nx)) {
            memcpy(x, y, 6 * (size_t)ny * sizeof *x);
            nx = ny;
        }
    }
    for (int k = 0; k < nx; k++) {
        (*candidates)++;
        double err = closed_polish(&p->k, p->dh, p->scale, Tt, tol, x + 6 * k);
        if (!(err <= tol)) continue;
        for (int i = 0; i < 6; i++) x[6 * k + i] = i == 2 ? closed_wrap4(x[6 * k + i]) : closed_wrap(x[6 * k + i]);
        closed_apair_keep(p->k.amp, qj, ej, found, x + 6 * k, err);
        if (continuum) *flags |= 1;
    }
}

int apair_ik_parallel_apair_prepare(void *design, const double *dh, double amplitude, double scale)
{
    apair_design *d = (apair_design *)design;
    parallel_design *p = &d->p;
    if (closed_fk_init(&p->k, dh) || !(scale > 0) || !(amplitude > 0 && isfinite(amplitude)) ||
        APAIR_IK_PARALLEL_APAIR_POSITION6_INVARIANTS > CLOSED_INV_MAX)
        return -1;
    memcpy(p->dh, dh, sizeof p->dh);
    p->scale = scale;
    for (int i = 0; i < 6; i++) { p->ca[i] = cos(dh[4 * i + 1]); p->sa[i] = sin(dh[4 * i + 1]); p->phi[i] = dh[4 * i + 3]; }
    /* axes 2, 3, 4 parallel, UR's wrist (cos alpha_4 = cos alpha_5 = 0, a_4 = a_5 = 0), sin phi_3 = 0, a_2 a_3 != 0 */
    if (fabs(p->sa[1]) > CLOSED_FLAT || fabs(p->sa[2]) > CLOSED_FLAT || fabs(p->ca[3]) > CLOSED_FLAT ||
        fabs(p->ca[4]) > CLOSED_FLAT || fabs(dh[12]) > CLOSED_FLAT * scale || fabs(dh[16]) > CLOSED_FLAT * scale ||
        fabs(sin(dh[11])) > CLOSED_FLAT || fabs(dh[4]) <= CLOSED_FLAT * scale || fabs(dh[8]) <= CLOSED_FLAT * scale)
        return -1;
    p->eps = p->ca[1] * p->ca[2];
    p->P = -p->eps * p->sa[3] * p->sa[4];
    p->Q = 0.0;
    p->which = 1;
    p->o3[0] = dh[12];
    p->o3[1] = dh[14] * p->sa[3];
    p->o3[2] = dh[14] * p->ca[3];
    p->k.amp[2] = amplitude;
    d->h = amplitude;
    d->law[0] = d->law[1] = 0.5 * amplitude * amplitude; /* d_3^2 = h^2 cos^2(theta_3/2) = kappa_0 + kappa_1 cos theta_3 */
    d->cphi3 = cos(dh[11]);
    d->quartic = fabs(dh[18]) <= CLOSED_FLAT * scale;
    apair_ik_parallel_apair_position6_invariants(dh, d->law, p->inv_pos);
    return 0;
}

void apair_ik_parallel_apair_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej, int *found,
                                    int *candidates, int *flags)
{
    const apair_design *d = (const apair_design *)design;
    const parallel_design *p = &d->p;
    const double *dh = p->dh;
    double L[6], P, gh[10], poly[13];
    *found = *candidates = *flags = 0;
    apair_ik_parallel_apair_position6_core(p->inv_pos, dh, Tt, d->law, L, &P, gh, poly);
    double big = p->scale + sqrt(Tt[3] * Tt[3] + Tt[7] * Tt[7] + Tt[11] * Tt[11]);
    double gref = big * big * (2 * fabs(dh[4] * dh[8]) + d->h * d->h); /* the size of G's terms */
    double psi1s[CLOSED_ROOTS + 1];
    int n1 = d->quartic ? closed_half_angles(4, gh, gref, psi1s) : closed_half_angles(12, poly, gref * gref, psi1s);
    if (n1 < 0) { *flags = -1; return; } /* the polynomial vanishes: not separated */
    const double *g = gh, *h = gh + 5, ca6 = p->ca[5], sa6 = p->sa[5];
    double z5[3];
    for (int r = 0; r < 3; r++) z5[r] = Tt[4 * r + 1] * sa6 + Tt[4 * r + 2] * ca6;
    for (int k1 = 0; k1 < n1; k1++) {
        double psi1 = psi1s[k1], c1 = cos(psi1), s1 = sin(psi1);
        double l1 = L[0] + L[1] * c1 + L[2] * s1, l2 = L[3] + L[4] * c1 + L[5] * s1, c5 = l1 / P;
        if (!(fabs(c5) <= 1 + 1e-6)) continue;
        c5 = fmin(1.0, fmax(-1.0, c5));
        /* G and H at psi_1 (at t = infinity, psi_1 = pi: their leading coefficients) */
        double gv = 0.0, hv = 0.0, size = 0.0;
        if (k1 == n1 - 1 && psi1 == CLOSED_PI) {
            double mg = 0.0, mh = 0.0;
            for (int k = 0; k < 5; k++) { mg = fmax(mg, fabs(g[k])); mh = fmax(mh, fabs(h[k])); }
            gv = g[4]; hv = h[4]; size = mg + mh;
        } else {
            double t = tan(0.5 * psi1), pk = 1.0;
            for (int k = 0; k < 5; k++, pk *= t) { gv += g[k] * pk; hv += h[k] * pk; size += (fabs(g[k]) + fabs(h[k])) * fabs(pk); }
        }
        double z1[3] = {p->sa[0] * s1, -p->sa[0] * c1, p->ca[0]}, u[3];
        double cx = z1[1] * z5[2] - z1[2] * z5[1], cy = z1[2] * z5[0] - z1[0] * z5[2], cz = z1[0] * z5[1] - z1[1] * z5[0];
        double psi5s[2];
        int n5;
        if (!d->quartic && fabs(gv) > 1e-6 * size) { /* |sin psi_5| = |z_3 x z_5| with the sign of H/G (which
                                                       * loses digits where G and H nearly vanish) */
            if (!(fabs(hv / gv) <= 1 + 1e-6)) continue;
            psi5s[0] = atan2(copysign(sqrt(cx * cx + cy * cy + cz * cz), hv / gv), c5);
            n5 = 1;
        } else { /* G vanishes with H: both signs */
            double base = acos(c5);
            n5 = base <= 1e-7 || base >= CLOSED_PI - 1e-7 ? 1 : 2;
            psi5s[0] = base <= 1e-7 ? 0.0 : base >= CLOSED_PI - 1e-7 ? CLOSED_PI : base;
            psi5s[1] = -base;
        }
        for (int k = 0; k < 3; k++) u[k] = z1[0] * Tt[k] + z1[1] * Tt[4 + k] + z1[2] * Tt[8 + k];
        double vx = p->eps * u[0], vy = p->eps * (u[1] * ca6 - u[2] * sa6);
        for (int k5 = 0; k5 < n5; k5++) {
            double psi5 = psi5s[k5], s5 = sin(psi5), cc5 = cos(psi5);
            double wx = p->sa[3] * s5, wy = p->sa[3] * cc5 * p->ca[4] + p->ca[3] * p->sa[4];
            if (hypot(wx, wy) > CLOSED_SINGULAR) {
                apair_elbows(d, Tt, tol, l2, psi1, psi5, atan2(wy * vx - wx * vy, wx * vx + wy * vy), 0, qj, ej, found,
                             candidates, flags);
                continue;
            }
            /* axis 6 parallel to axes 2-4: the slide pins the elbow (kappa_1 cos phi_3 cos psi_3 = L_2^2 - kappa_0)
             * and so the point of the circle frame 3's origin runs on as psi_6 turns */
            double a2 = dh[4], a3 = dh[8], c3 = (l2 * l2 - d->law[0]) / (d->law[1] * d->cphi3), A, B, C;
            if (!(fabs(c3) <= 1 + 1e-6)) continue;
            circle(p, dh, Tt, psi1, psi5, &A, &B, &C);
            double K = hypot(B, C);
            if (!(K > CLOSED_FLAT * (a2 * a2 + a3 * a3))) { /* a point: psi_6 free, the R-arm's member */
                apair_elbows(d, Tt, tol, l2, psi1, psi5, free_psi6(p, dh, Tt, psi1, psi5), 1, qj, ej, found, candidates,
                             flags);
                continue;
            }
            double x = (a2 * a2 + a3 * a3 + 2 * a2 * a3 * fmin(1.0, fmax(-1.0, c3)) - A) / K;
            if (!(fabs(x) <= 1 + 1e-6)) continue;
            double base = atan2(C, B), turn = acos(fmin(1.0, fmax(-1.0, x)));
            apair_elbows(d, Tt, tol, l2, psi1, psi5, base + turn, 0, qj, ej, found, candidates, flags);
            if (turn > 1e-7) apair_elbows(d, Tt, tol, l2, psi1, psi5, base - turn, 0, qj, ej, found, candidates, flags);
        }
    }
    closed_sort(qj, ej, *found);
}

/* ---- A UR-like arm with sinusoidal A-pairs at joint 1 (cos alpha_1 = 0) and/or joint 5 (cos alpha_4 = 0)
 * (apair.ik.parallel_slides, where the steps are explained): their slides run along axes at right
 * angles to the parallel axes 2-4, so L_1 and L_2 of the R-arm's first step do not see them
 * (derivations/chain_ik_parallel.py checks it) and psi_1 and psi_5 come as on the R-arm. Each of those
 * angles has two representatives theta in (-2 pi, 2 pi], the pair's slides h cos(theta/2) of
 * opposite signs; for each the R-arm's remaining steps run with c_1 + d_1 and c_5 + d_5: at most
 * 8 x 2 x 2 = 32 solutions. The design is the R-arm's (parallel_design) with the amplitudes in
 * k.amp, so the polish and the verification carry the pairs' laws. */

/* the representatives in (-2 pi, 2 pi] of a joint's angle from psi (mod 2 pi): theta, and for an
 * A-pair (amp != 0) theta -+ 2 pi too; their count */
static int slides_reps(double psi, double phi, double amp, double *theta)
{
    double t = closed_wrap(psi - phi);
    theta[0] = t;
    if (amp == 0.0) return 1;
    theta[1] = closed_wrap4(t - copysign(2 * CLOSED_PI, t));
    return 2;
}

int apair_ik_parallel_slides_prepare(void *design, const double *dh, const double *amplitude, double scale)
{
    parallel_design *p = (parallel_design *)design;
    if (apair_ik_parallel_prepare(design, dh, scale)) return -1;
    int any = 0;
    for (int i = 0; i < 6; i++) {
        if (!(amplitude[i] >= 0.0 && isfinite(amplitude[i]))) return -1;
        if (amplitude[i] == 0.0) continue;
        /* only joints 1 and 5, each sliding at right angles to the parallel axes */
        if ((i != 0 && i != 4) || fabs(p->ca[i == 0 ? 0 : 3]) > CLOSED_FLAT) return -1;
        p->k.amp[i] = amplitude[i];
        any = 1;
    }
    return any ? 0 : -1;
}

void apair_ik_parallel_slides_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej,
                                     int *found, int *candidates, int *flags)
{
    const parallel_design *p = (const parallel_design *)design;
    const double *amp = p->k.amp, eps = p->eps;
    double scale = p->scale, L[6], psi1s[CLOSED_ROOTS + 1];
    *found = *candidates = *flags = 0;
    int n1 = first_step(p, Tt, L, psi1s);
    if (n1 < 0) { *flags = -1; return; } /* the polynomial vanishes: not separated */
    double z5[3], ca6 = p->ca[5], sa6 = p->sa[5], dh[24];
    for (int r = 0; r < 3; r++) z5[r] = Tt[4 * r + 1] * sa6 + Tt[4 * r + 2] * ca6;
    memcpy(dh, p->dh, sizeof dh);
    for (int k1 = 0; k1 < n1; k1++) {
        double psi1 = psi1s[k1], c1 = cos(psi1), s1 = sin(psi1);
        double l1 = L[0] + L[1] * c1 + L[2] * s1, l2 = L[3] + L[4] * c1 + L[5] * s1;
        double z1[3] = {p->sa[0] * s1, -p->sa[0] * c1, p->ca[0]}, psi5s[2], u[3], th1[2], th5[2];
        int n5 = psi5_of(p, l1, l2, z1, z5, psi5s), m1 = slides_reps(psi1, p->phi[0], amp[0], th1);
        for (int k = 0; k < 3; k++) u[k] = z1[0] * Tt[k] + z1[1] * Tt[4 + k] + z1[2] * Tt[8 + k];
        double vx = eps * u[0], vy = eps * (u[1] * ca6 - u[2] * sa6);
        for (int k5 = 0; k5 < n5; k5++) {
            double psi5 = psi5s[k5], s5 = sin(psi5), cc5 = cos(psi5);
            double wx = p->sa[3] * s5, wy = p->sa[3] * cc5 * p->ca[4] + p->ca[3] * p->sa[4];
            int singular = hypot(wx, wy) <= CLOSED_SINGULAR; /* axis 6 parallel to axes 2-4: psi_6 free */
            int m5 = slides_reps(psi5, p->phi[4], amp[4], th5);
            for (int j1 = 0; j1 < m1; j1++)
                for (int j5 = 0; j5 < m5; j5++) {
                    dh[2] = p->dh[2] + amp[0] * cos(0.5 * th1[j1]); /* c_1 + d_1, c_5 + d_5 */
                    dh[18] = p->dh[18] + amp[4] * cos(0.5 * th5[j5]);
                    double psi6 = singular ? free_psi6(p, dh, Tt, psi1, psi5)
                                           : atan2(wy * vx - wx * vy, wx * vx + wy * vy), x[12];
                    int nx = inner(p, dh, scale, Tt, psi1, psi5, psi6, x, flags, 4 * CLOSED_DOUBLE);
                    for (int k = 0; k < nx; k++) {
                        double *xk = x + 6 * k;
                        xk[0] = th1[j1];
                        xk[4] = th5[j5];
                        (*candidates)++;
                        double err = closed_polish(&p->k, p->dh, scale, Tt, tol, xk);
                        if (!(err <= tol)) continue;
                        for (int i = 0; i < 6; i++) xk[i] = amp[i] != 0.0 ? closed_wrap4(xk[i]) : closed_wrap(xk[i]);
                        closed_apair_keep(amp, qj, ej, found, xk, err);
                        if (singular) *flags |= 1;
                    }
                }
        }
    }
    closed_sort(qj, ej, *found);
}

int apair_ik_parallel_apair(const double *dh, const double *amplitude, double scale, size_t count,
                            const double *target, ptrdiff_t target_stride, double tol, double *q, double *error,
                            int *found, int *candidates, int *flags)
{
    apair_ik_closed solver;
    if (apair_ik_closed_init_apair(&solver, dh, amplitude, scale) ||
        (solver.family != APAIR_IK_PARALLEL_APAIR && solver.family != APAIR_IK_PARALLEL_SLIDES))
        return -1;
    return apair_ik_closed_solve(&solver, count, target, target_stride, tol, q, error, found, candidates, flags);
}

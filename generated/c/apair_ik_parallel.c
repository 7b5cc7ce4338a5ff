/*
 * A copy of src/csrc/apair_ik_parallel.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik_parallel.c. Content hash: 8f832873b4ffd8ad
 */
/*
 * The closed-form inverse kinematics of six-joint R-chains with axes 2, 3 and 4 parallel (UR arms;
 * apair.ik.parallel, where the steps are explained): the derived kernel ik_parallel_position6
 * (derivations/chain_ik_parallel.py) gives L_1(psi_1) = P cos psi_5, L_2(psi_1) = Q sin psi_5 and
 * the polynomial in t = tan(psi_1/2) whose real roots give psi_1; psi_5, psi_6, the elbow's psi_3,
 * psi_2 and psi_4 follow in closed form, and each candidate gets up to two Gauss-Newton steps on
 * fk6 and jacobian6 and is kept where fk reproduces the pose to tol (apair_ik_closed.h, shared with
 * apair_ik_wrist.c). Hand-written C: the C backend of codegen copies it into generated/c, the
 * library it belongs to. Declared in apair.h (template: codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_closed.h"

typedef struct {
    closed_fk k;
    int which; /* 0: the quartic; 1: L_2's quadratic (Q = 0, a_5 = 0); 2: L_1's (P = 0, axes 5 and 6 parallel) */
    double dh[24], scale, eps, P, Q, ca[6], sa[6], phi[6], o3[3];
    double inv_pos[CLOSED_INV_MAX];
} parallel_design;

static void inv34(const double *A, double *B) /* the inverse of a rigid 3 x 4 transform */
{
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++) B[4 * r + k] = A[4 * k + r];
        B[4 * r + 3] = -(A[r] * A[3] + A[4 + r] * A[7] + A[8 + r] * A[11]);
    }
}

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
    inv34(A1, I1);
    inv34(A5, I5);
    inv34(A6, I6);
    closed_mul34(I1, T34, N);
    closed_mul34(N, I6, N);
    closed_mul34(N, I5, N);
    for (int r = 0; r < 2; r++) O3[r] = N[4 * r + 3] - (N[4 * r] * p->o3[0] + N[4 * r + 1] * p->o3[1] + N[4 * r + 2] * p->o3[2]);
}

/* Where axis 6 is parallel to axes 2-4, psi_6 is free: frame 3's origin then runs on a circle as
 * psi_6 turns, rho^2 = A + B cos psi_6 + C sin psi_6; the member taken has the elbow at cos psi_3 = 0
 * (rho^2 = a_2^2 + a_3^2, the middle of its range) where the circle reaches it, else the nearest. */
static double free_psi6(const parallel_design *p, const double *dh, const double *Tt, double psi1, double psi5)
{
    double N[12], O3[2], r[3];
    for (int k = 0; k < 3; k++) {
        frame3(p, dh, Tt, psi1, psi5, k * CLOSED_PI / 2, N, O3);
        r[k] = O3[0] * O3[0] + O3[1] * O3[1];
    }
    double A = 0.5 * (r[0] + r[2]), B = 0.5 * (r[0] - r[2]), C = r[1] - A, K = hypot(B, C);
    double a2 = dh[4], a3 = dh[8], scale2 = a2 * a2 + a3 * a3;
    if (!(K > CLOSED_FLAT * scale2)) return 0.0;
    return atan2(C, B) + acos(fmin(1.0, fmax(-1.0, (scale2 - A) / K)));
}

/* psi_2, psi_3, psi_4 of the planar problem left by psi_1, psi_5, psi_6 (per elbow, at most 2):
 * candidates x = psi - phi */
static int inner(const parallel_design *p, const double *dh, double scale, const double *Tt, double psi1, double psi5,
                 double psi6, double *x, int *flags)
{
    double N[12], O3[2];
    frame3(p, dh, Tt, psi1, psi5, psi6, N, O3); /* N = A_2 A_3 A_4 */
    double a2 = dh[4], a3 = dh[8], rho2 = O3[0] * O3[0] + O3[1] * O3[1];
    double c3 = (rho2 - a2 * a2 - a3 * a3) / (2 * a2 * a3);
    if (!(fabs(c3) <= 1 + 1e-6)) return 0;
    double rest = 1 - c3 * c3, s3 = rest <= 4 * CLOSED_DOUBLE ? 0.0 : sqrt(rest);
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

void apair_ik_parallel_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej, int *found,
                              int *candidates, int *flags)
{
    const parallel_design *p = (const parallel_design *)design;
    const double *dh = p->dh, eps = p->eps;
    double scale = p->scale, L[6], PQ[2], quartic[5], qa[3], qb[3];
    *found = *candidates = *flags = 0;
    apair_ik_parallel_position6_core(p->inv_pos, dh, Tt, L, PQ, quartic, qa, qb);
    const double *c = p->which == 0 ? quartic : p->which == 1 ? qb : qa;
    int deg = p->which == 0 ? 4 : 2;
    double big = scale + sqrt(Tt[3] * Tt[3] + Tt[7] * Tt[7] + Tt[11] * Tt[11]);
    double ref = p->which == 0 ? (big * p->P) * (big * p->P) + p->Q * p->Q : p->which == 1 ? big : 1.0;
    double psi1s[CLOSED_ROOTS + 1];
    int n1 = closed_half_angles(deg, c, ref, psi1s);
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
            int nx = inner(p, dh, scale, Tt, psi1s[k1], psi5s[k5], psi6, x, flags);
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

/*
 * A copy of src/csrc/apair_ik_wrist.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik_wrist.c. Content hash: 0235f446878a46c1
 */
/*
 * The closed-form inverse kinematics of six-joint R-chains with a spherical wrist (apair.ik.wrist,
 * where the steps are explained): the derived kernel ik_wrist_position6 (derivations/
 * chain_ik_wrist.py) gives the wrist point and the polynomial in t = tan(psi_3/2); its real roots
 * (isolated between the real roots of its derivatives, then bisected) give psi_3, the shoulder's
 * psi_1, psi_2 and the wrist's psi_4, psi_5, psi_6 follow in closed form, and each candidate gets up
 * to two Gauss-Newton steps on fk6 and jacobian6 and is kept where fk reproduces the pose to tol
 * (apair_ik_closed.h, shared with apair_ik_parallel.c). The same wrist steps serve an arm with axes
 * 2 and 3 parallel and a sinusoidal A-pair at joint 3 or at joint 1 (below, after the R-arm's). Hand-written C: the C backend of codegen copies it into generated/c, the library it belongs to.
 * Declared in apair.h (template: codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_closed.h"

#define WRIST_CONTINUUM 1e-6 /* a verified solution this close to axes 4 and 6 in line is one of their continuum */

typedef struct {
    closed_fk k;
    double dh[24], scale, ca6, sa6;
    int which;               /* 0: quartic; 1: (A), a_1 = 0; 2: (B), sin alpha_1 = 0 */
    double a1, ca1, sa1, B2[12], m3[3], ca4, sa4, ca5, sa5, alpha[6], phi[6], ca[6], sa[6];
    double inv_pos[CLOSED_INV_MAX];
} wrist_design;

/* psi_1, psi_2 for the wrist point W at psi_3 (p: its position in frame 1 before psi_2) */
static int shoulder(const wrist_design *w, double scale, const double *W, double r, double h, const double *p,
                    double *psi12, int *flags)
{
    double pxy2 = p[0] * p[0] + p[1] * p[1], pp = pxy2 + p[2] * p[2], u[4];
    int nu = 0;
    if (w->which == 0) {
        u[0] = (r - w->a1 * w->a1 - pp) / (2 * w->a1);
        u[1] = (h - w->ca1 * p[2]) / w->sa1;
        nu = 1;
    } else {
        double known = w->which == 1 ? (h - w->ca1 * p[2]) / w->sa1 : (r - w->a1 * w->a1 - pp) / (2 * w->a1);
        double rest = pxy2 - known * known;
        if (rest < -1e-6 * (pxy2 + scale * scale)) return 0;
        /* a double root (rest 0, rounded): sqrt would put both signs 1e-8 off it */
        double other = rest <= CLOSED_DOUBLE * (pxy2 + scale * scale) ? 0.0 : sqrt(rest);
        for (int s = 0; s < (other > 0 ? 2 : 1); s++) {
            double o = s ? -other : other;
            u[2 * nu] = w->which == 1 ? o : known;
            u[2 * nu + 1] = w->which == 1 ? known : o;
            nu++;
        }
    }
    double tiny = (CLOSED_FLAT * scale) * (CLOSED_FLAT * scale);
    for (int k = 0; k < nu; k++) {
        double ux = u[2 * k], uy = u[2 * k + 1], vx = w->a1 + ux, vy = w->ca1 * uy - w->sa1 * p[2];
        /* the turn taking (x1, y1) to (x2, y2) in one atan2 */
        if (pxy2 <= tiny) { *flags |= 4; psi12[2 * k + 1] = 0.0; }
        else psi12[2 * k + 1] = atan2(p[0] * uy - p[1] * ux, p[0] * ux + p[1] * uy);
        if (W[0] * W[0] + W[1] * W[1] <= tiny && vx * vx + vy * vy <= tiny) { *flags |= 2; psi12[2 * k] = 0.0; }
        else psi12[2 * k] = atan2(vx * W[1] - vy * W[0], vx * W[0] + vy * W[1]);
    }
    return nu;
}

/* psi_4, psi_5, psi_6 from M = R_3^T R_6 Rx(alpha_6)^T = Rz(psi_4) Rx(alpha_4) Rz(psi_5) Rx(alpha_5) Rz(psi_6) */
static int wrist(const wrist_design *w, const double *M, double *psi456, int *flags)
{
    double c5 = (w->ca4 * w->ca5 - M[8]) / (w->sa4 * w->sa5);
    if (!(fabs(c5) <= 1 + 1e-6)) return 0;
    /* |sin psi_5| from |M e_z|'s (x, y) = |q|, exact near the wrist's singular psi_5 (acos is not) */
    double qy0 = w->ca4 * fmin(1.0, fmax(-1.0, c5)) * w->sa5 + w->sa4 * w->ca5;
    double s5a = sqrt(fmax(0.0, M[2] * M[2] + M[5] * M[5] - qy0 * qy0)) / fabs(w->sa5);
    double base = atan2(s5a, c5);
    if (base <= CLOSED_SINGULAR) base = 0.0;
    else if (base >= CLOSED_PI - CLOSED_SINGULAR) base = CLOSED_PI;
    int n = 0;
    for (int s = 0; s < (base > 0 && base < CLOSED_PI ? 2 : 1); s++) {
        double psi5 = s ? -base : base, s5 = sin(psi5), cs5 = cos(psi5);
        double qx = s5 * w->sa5, qy = -w->ca4 * cs5 * w->sa5 - w->sa4 * w->ca5;
        double *out = psi456 + 3 * n++;
        out[1] = psi5;
        if (hypot(qx, qy) <= CLOSED_SINGULAR) { /* axes 4 and 6 in line: psi_4 = 0, psi_6 from N = (Rx Rz Rx)^T M */
            *flags |= 1;
            double ca4 = w->ca4, sa4 = w->sa4, ca5 = w->ca5, sa5 = w->sa5;
            /* K = Rx(alpha_4) Rz(psi_5) Rx(alpha_5), columns 0 and 1 of N = K^T M need K's rows . M's columns */
            double K[9] = {cs5, -s5 * ca5, s5 * sa5,
                           ca4 * s5, ca4 * cs5 * ca5 - sa4 * sa5, -ca4 * cs5 * sa5 - sa4 * ca5,
                           sa4 * s5, sa4 * cs5 * ca5 + ca4 * sa5, -sa4 * cs5 * sa5 + ca4 * ca5};
            double n00 = K[0] * M[0] + K[3] * M[3] + K[6] * M[6];
            double n10 = K[1] * M[0] + K[4] * M[3] + K[7] * M[6];
            out[0] = 0.0;
            out[2] = atan2(n10, n00);
            continue;
        }
        out[0] = atan2(qx * M[5] - qy * M[2], qx * M[2] + qy * M[5]); /* q turned onto M e_z's (x, y) */
        double sx = w->sa4 * s5, sy = w->sa4 * cs5 * w->ca5 + w->ca4 * w->sa5;
        out[2] = atan2(M[6] * sy - M[7] * sx, M[6] * sx + M[7] * sy); /* (M_31, M_32) turned onto s */
    }
    return n;
}

/* A solution with axes 4 and 6 in line (K = Rx(alpha_4) Rz(psi_5) Rx(alpha_5) keeps e_z, K_33 = s = +-1)
 * is one of the continuum psi_4 + s psi_6 = const: replaced by its member with psi_4 = 0 where that
 * verifies (flag 1); the error of what is kept. */
static double canonical_wrist(const wrist_design *w, const double *dh, double scale, const double *Tt, double tol,
                              double *x, double err, int *flags)
{
    double psi5 = x[4] + w->phi[4], s5 = sin(psi5), c5 = cos(psi5);
    if (hypot(s5 * w->sa5, w->ca4 * c5 * w->sa5 + w->sa4 * w->ca5) > WRIST_CONTINUUM) return err;
    double s = w->ca4 * w->ca5 - w->sa4 * w->sa5 * c5 < 0 ? -1.0 : 1.0, y[6], e[6];
    memcpy(y, x, sizeof y);
    y[5] = closed_wrap(x[5] + w->phi[5] + s * (x[3] + w->phi[3]) - w->phi[5]);
    y[3] = closed_wrap(-w->phi[3]);
    double err2 = closed_evaluate(&w->k, dh, scale, y, Tt, e, NULL);
    if (!(err2 <= tol)) return err;
    memcpy(x, y, sizeof y);
    *flags |= 1;
    return err2;
}

/* the prepared design lives in apair_ik_closed's storage */
typedef char wrist_design_fits[sizeof(wrist_design) <= sizeof(((apair_ik_closed *)0)->design) ? 1 : -1];

int apair_ik_wrist_prepare(void *design, const double *dh, double scale)
{
    wrist_design *w = (wrist_design *)design;
    if (closed_fk_init(&w->k, dh) || !(scale > 0) || APAIR_IK_WRIST_POSITION6_INVARIANTS > CLOSED_INV_MAX) return -1;
    memcpy(w->dh, dh, sizeof w->dh);
    w->scale = scale;
    for (int i = 0; i < 6; i++) { w->alpha[i] = dh[4 * i + 1]; w->phi[i] = dh[4 * i + 3]; }
    apair_ik_wrist_position6_invariants(dh, w->inv_pos);
    w->a1 = dh[0]; w->ca1 = cos(dh[1]); w->sa1 = sin(dh[1]);
    w->which = fabs(w->a1) <= CLOSED_FLAT * scale ? 1 : fabs(w->sa1) <= CLOSED_FLAT ? 2 : 0;
    for (int i = 0; i < 6; i++) { w->ca[i] = cos(dh[4 * i + 1]); w->sa[i] = sin(dh[4 * i + 1]); }
    closed_dh4(dh[4], w->ca[1], w->sa[1], dh[6], 0.0, w->B2);
    {
        double A3[12];
        closed_dh4(dh[8], w->ca[2], w->sa[2], dh[10], 0.0, A3);
        for (int r = 0; r < 3; r++) w->m3[r] = A3[4 * r + 2] * dh[14] + A3[4 * r + 3];
    }
    w->ca4 = cos(dh[13]); w->sa4 = sin(dh[13]); w->ca5 = cos(dh[17]); w->sa5 = sin(dh[17]);
    w->ca6 = cos(dh[21]);
    w->sa6 = sin(dh[21]);
    return fabs(w->sa4 * w->sa5) <= CLOSED_FLAT ? -1 : 0; /* not a wrist: axes 4, 5 or 5, 6 parallel */
}

void apair_ik_wrist_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej, int *found,
                           int *candidates, int *flags)
{
    const wrist_design *w = (const wrist_design *)design;
    double W[3], rh[2], quartic[5], qa[3], qb[3];
    *found = *candidates = *flags = 0;
    apair_ik_wrist_position6_core(w->inv_pos, w->dh, Tt, W, rh, quartic, qa, qb);
    const double *c = w->which == 0 ? quartic : w->which == 1 ? qa : qb;
    int deg = w->which == 0 ? 4 : 2;
    double big = rh[0] + w->scale * w->scale, ref = w->which == 0 ? big * big : w->which == 1 ? big : sqrt(big);
    double psi3[CLOSED_ROOTS + 1];
    int n3 = closed_half_angles(deg, c, ref, psi3);
    if (n3 < 0) { *flags = -1; return; } /* the polynomial vanishes: not separated */
    double R6[9] = {Tt[0], Tt[1], Tt[2], Tt[4], Tt[5], Tt[6], Tt[8], Tt[9], Tt[10]};
    for (int k3 = 0; k3 < n3; k3++) {
        double c3 = cos(psi3[k3]), s3 = sin(psi3[k3]);
        double m[3] = {c3 * w->m3[0] - s3 * w->m3[1], s3 * w->m3[0] + c3 * w->m3[1], w->m3[2]}, p[3];
        for (int r = 0; r < 3; r++) p[r] = w->B2[4 * r] * m[0] + w->B2[4 * r + 1] * m[1] + w->B2[4 * r + 2] * m[2] + w->B2[4 * r + 3];
        double psi12[4];
        int n12 = shoulder(w, w->scale, W, rh[0], rh[1], p, psi12, flags);
        for (int k12 = 0; k12 < n12; k12++) {
            double A1[12], A2[12], A3[12], A[12], M[9], R6x[9];
            closed_dh4(w->dh[0], w->ca[0], w->sa[0], w->dh[2], psi12[2 * k12], A1);
            closed_dh4(w->dh[4], w->ca[1], w->sa[1], w->dh[6], psi12[2 * k12 + 1], A2);
            closed_dh4(w->dh[8], w->ca[2], w->sa[2], w->dh[10], psi3[k3], A3);
            closed_mul34(A1, A2, A);
            closed_mul34(A, A3, A);
            /* R6 Rx(alpha_6)^T, then M = R_3^T (R6 Rx^T) */
            for (int r = 0; r < 3; r++) {
                R6x[3 * r] = R6[3 * r];
                R6x[3 * r + 1] = R6[3 * r + 1] * w->ca6 - R6[3 * r + 2] * w->sa6;
                R6x[3 * r + 2] = R6[3 * r + 1] * w->sa6 + R6[3 * r + 2] * w->ca6;
            }
            for (int r = 0; r < 3; r++)
                for (int k = 0; k < 3; k++) M[3 * r + k] = A[r] * R6x[k] + A[4 + r] * R6x[3 + k] + A[8 + r] * R6x[6 + k];
            double psi456[6];
            int n456 = wrist(w, M, psi456, flags);
            for (int k456 = 0; k456 < n456; k456++) {
                double x[6] = {psi12[2 * k12], psi12[2 * k12 + 1], psi3[k3], psi456[3 * k456], psi456[3 * k456 + 1],
                               psi456[3 * k456 + 2]};
                for (int i = 0; i < 6; i++) x[i] = closed_wrap(x[i] - w->phi[i]);
                (*candidates)++;
                double err = closed_polish(&w->k, w->dh, w->scale, Tt, tol, x);
                if (!(err <= tol)) continue;
                err = canonical_wrist(w, w->dh, w->scale, Tt, tol, x, err, flags);
                for (int i = 0; i < 6; i++) x[i] = closed_wrap(x[i]);
                closed_keep(qj, ej, found, x, err);
            }
        }
    }
    closed_sort(qj, ej, *found);
}

int apair_ik_wrist(const double *dh, double scale, size_t count, const double *target, ptrdiff_t target_stride,
                   double tol, double *q, double *error, int *found, int *candidates, int *flags)
{
    apair_ik_closed solver;
    if (apair_ik_closed_init(&solver, APAIR_IK_WRIST, dh, scale)) return -1;
    return apair_ik_closed_solve(&solver, count, target, target_stride, tol, q, error, found, candidates, flags);
}

/* ---- A spherical-wrist arm with axes 2 and 3 parallel and a sinusoidal A-pair at joint 3
 * (apair.ik.wrist_apair, where the steps are explained): the derived kernel ik_wrist_apair_position6
 * (derivations/chain_ik_wrist_apair.py) gives W, L = cos alpha_2 d_3 in (1, cos psi_1, sin psi_1), E_s and,
 * in t = tan(psi_1/2), kappa cos psi_3 and kappa E_s sin psi_3 and the polynomial of degree 8 whose
 * real roots give psi_1; psi_3 = atan2 of the two, psi_2 turns the elbow's plane onto W - O_1 in
 * frame 1, and the wrist's angles follow as on the R-arm above; theta_3 is the angle in (-2 pi, 2 pi]
 * whose slide h cos(theta_3/2) has the sign of cos alpha_2 L, with its twin where it is near +-pi. */

typedef struct {
    wrist_design w; /* the R-arm's wrist steps; its inv_pos holds ik_wrist_apair_position6's invariants */
    double law[2];
} wrist_apair_design;

/* the prepared design lives in apair_ik_closed's storage */
typedef char wrist_apair_design_fits[sizeof(wrist_apair_design) <= sizeof(((apair_ik_closed *)0)->design) ? 1 : -1];

/* p(psi_3): the wrist point in frame 1 before the turn psi_2 */
static void elbow_point(const wrist_design *w, double psi3, double *p)
{
    double c3 = cos(psi3), s3 = sin(psi3), m[3] = {c3 * w->m3[0] - s3 * w->m3[1], s3 * w->m3[0] + c3 * w->m3[1], w->m3[2]};
    for (int r = 0; r < 3; r++) p[r] = w->B2[4 * r] * m[0] + w->B2[4 * r + 1] * m[1] + w->B2[4 * r + 2] * m[2] + w->B2[4 * r + 3];
}

/* R_6 Rx(alpha_6)^T (3 x 3) from the pose T */
static void tool_rotation(const wrist_design *w, const double *Tt, double *R6x)
{
    for (int r = 0; r < 3; r++) {
        R6x[3 * r] = Tt[4 * r];
        R6x[3 * r + 1] = Tt[4 * r + 1] * w->ca6 - Tt[4 * r + 2] * w->sa6;
        R6x[3 * r + 2] = Tt[4 * r + 1] * w->sa6 + Tt[4 * r + 2] * w->ca6;
    }
}

/* The candidates of an arm with an A-pair at joint at + 1 (0 or 2) at psi_1, psi_2, psi_3 (A1: joint 1's
 * transform at psi_1, with its slide), the pair's angle theta: the wrist's angles from M = R_3^T R6x, then each
 * candidate (and, where `twin`, its twin -theta where theta is near +-pi: the slide 0) polished, made
 * canonical and kept */
static void apair_wrist_keep(const wrist_design *w, const double *Tt, double tol, const double *R6x, const double *A1,
                             double psi1, double psi2, double psi3, int at, double theta, int twin, double *qj,
                             double *ej, int *found, int *candidates, int *flags)
{
    const double *dh = w->dh, *amp = w->k.amp;
    double A2[12], A3[12], A[12], M[9], psi456[6];
    closed_dh4(dh[4], w->ca[1], w->sa[1], dh[6], psi2, A2);
    closed_dh4(dh[8], w->ca[2], w->sa[2], dh[10], psi3, A3);
    closed_mul34(A1, A2, A);
    closed_mul34(A, A3, A);
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++) M[3 * r + k] = A[r] * R6x[k] + A[4 + r] * R6x[3 + k] + A[8 + r] * R6x[6 + k];
    int n456 = wrist(w, M, psi456, flags), twins = twin && fabs(fabs(theta) - CLOSED_PI) <= 1e-4 ? 2 : 1;
    for (int k456 = 0; k456 < n456; k456++)
        for (int tw = 0; tw < twins; tw++) {
            double x[6] = {psi1, psi2, psi3, psi456[3 * k456], psi456[3 * k456 + 1], psi456[3 * k456 + 2]};
            for (int i = 0; i < 6; i++) x[i] = closed_wrap(x[i] - w->phi[i]);
            x[at] = tw ? -theta : theta;
            (*candidates)++;
            double err = closed_polish(&w->k, dh, w->scale, Tt, tol, x);
            if (!(err <= tol)) continue;
            err = canonical_wrist(w, dh, w->scale, Tt, tol, x, err, flags);
            for (int i = 0; i < 6; i++) x[i] = amp[i] != 0.0 ? closed_wrap4(x[i]) : closed_wrap(x[i]);
            closed_apair_keep(amp, qj, ej, found, x, err);
        }
}

int apair_ik_wrist_apair_prepare(void *design, const double *dh, double amplitude, double scale)
{
    wrist_apair_design *d = (wrist_apair_design *)design;
    wrist_design *w = &d->w;
    if (apair_ik_wrist_prepare(w, dh, scale) || !(amplitude > 0 && isfinite(amplitude)) ||
        APAIR_IK_WRIST_APAIR_POSITION6_INVARIANTS > CLOSED_INV_MAX)
        return -1;
    /* a spherical wrist (a_4 = a_5 = c_5 = 0), axes 2 and 3 parallel, sin phi_3 = 0, 2 a_2 sin alpha_3 c_4 != 0 */
    if (fabs(dh[12]) > CLOSED_FLAT * scale || fabs(dh[16]) > CLOSED_FLAT * scale || fabs(dh[18]) > CLOSED_FLAT * scale ||
        fabs(w->sa[1]) > CLOSED_FLAT || fabs(sin(dh[11])) > CLOSED_FLAT ||
        fabs(2 * dh[4] * w->sa[2] * dh[14]) <= CLOSED_FLAT * scale * scale)
        return -1;
    w->k.amp[2] = amplitude;
    d->law[0] = d->law[1] = 0.5 * amplitude * amplitude; /* d_3^2 = h^2 cos^2(theta_3/2) = kappa_0 + kappa_1 cos theta_3 */
    apair_ik_wrist_apair_position6_invariants(dh, d->law, w->inv_pos);
    return 0;
}

void apair_ik_wrist_apair_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej, int *found,
                                 int *candidates, int *flags)
{
    const wrist_apair_design *d = (const wrist_apair_design *)design;
    const wrist_design *w = &d->w;
    const double *dh = w->dh;
    double W[3], L[3], Es, cs[10], poly[9];
    *found = *candidates = *flags = 0;
    apair_ik_wrist_apair_position6_core(w->inv_pos, dh, Tt, d->law, W, L, &Es, cs, poly);
    double big = w->scale + sqrt(W[0] * W[0] + W[1] * W[1] + W[2] * W[2]), size = fabs(Es) * (big * big + d->law[1]);
    double psi1s[CLOSED_ROOTS + 1];
    int n1 = closed_half_angles(8, poly, size * size, psi1s);
    if (n1 < 0) { *flags = -1; return; } /* the polynomial vanishes: not separated */
    double R6x[9], tiny = (CLOSED_FLAT * w->scale) * (CLOSED_FLAT * w->scale);
    tool_rotation(w, Tt, R6x);
    for (int k1 = 0; k1 < n1; k1++) {
        double psi1 = psi1s[k1], cv, sv;
        if (k1 == n1 - 1 && psi1 == CLOSED_PI) { cv = cs[4]; sv = cs[9]; } /* t = infinity: the leading coefficients */
        else { double t = tan(0.5 * psi1); cv = closed_horner(4, cs, t); sv = closed_horner(4, cs + 5, t); }
        double psi3 = atan2(sv / Es, cv); /* kappa cos psi_3, kappa sin psi_3 */
        double A1[12], u[3], p[3];
        closed_dh4(dh[0], w->ca[0], w->sa[0], dh[2], psi1, A1);
        for (int k = 0; k < 3; k++) /* W - O_1 in frame 1 */
            u[k] = A1[k] * (W[0] - A1[3]) + A1[4 + k] * (W[1] - A1[7]) + A1[8 + k] * (W[2] - A1[11]);
        elbow_point(w, psi3, p);
        double psi2 = 0.0;
        if (p[0] * p[0] + p[1] * p[1] <= tiny) *flags |= 4; /* the wrist point on axis 2: psi_2 free */
        else psi2 = atan2(p[0] * u[1] - p[1] * u[0], p[0] * u[0] + p[1] * u[1]);
        /* theta_3: the representative whose slide has the sign of d_3 = cos alpha_2 L */
        double d3 = w->ca[1] * (L[0] + L[1] * cos(psi1) + L[2] * sin(psi1)), theta3 = closed_wrap(psi3 - w->phi[2]);
        if (cos(0.5 * theta3) * d3 < 0) theta3 -= copysign(2 * CLOSED_PI, theta3);
        apair_wrist_keep(w, Tt, tol, R6x, A1, psi1, psi2, psi3, 2, theta3, 1, qj, ej, found, candidates, flags);
    }
    closed_sort(qj, ej, *found);
}

/* ---- A spherical-wrist arm with axes 2 and 3 parallel and a sinusoidal A-pair at joint 1 (cos alpha_1 = 0;
 * apair.ik.wrist_slide1, where the steps are explained): the derived kernel ik_wrist_slide1_position6
 * gives W and the quadratic in t = tan(psi_1/2) whose real roots give psi_1; each has two representatives
 * theta_1 in (-2 pi, 2 pi] (slides of opposite signs), and for each the elbow's two psi_3 from
 * rho^2 = E_0 + E_c cos psi_3 + E_s sin psi_3, then psi_2 and the wrist as above: at most 16 solutions. */

typedef struct {
    wrist_design w; /* the R-arm's wrist steps; its inv_pos holds ik_wrist_slide1_position6's invariants */
    double E0, Ec, Es, h;
} wrist_slide1_design;

typedef char wrist_slide1_design_fits[sizeof(wrist_slide1_design) <= sizeof(((apair_ik_closed *)0)->design) ? 1 : -1];

int apair_ik_wrist_slide1_prepare(void *design, const double *dh, double amplitude, double scale)
{
    wrist_slide1_design *d = (wrist_slide1_design *)design;
    wrist_design *w = &d->w;
    if (apair_ik_wrist_prepare(w, dh, scale) || !(amplitude > 0 && isfinite(amplitude)) ||
        APAIR_IK_WRIST_SLIDE1_POSITION6_INVARIANTS > CLOSED_INV_MAX)
        return -1;
    /* a spherical wrist (a_4 = a_5 = c_5 = 0), axes 2 and 3 parallel, axis 1 at right angles to axis 2 */
    if (fabs(dh[12]) > CLOSED_FLAT * scale || fabs(dh[16]) > CLOSED_FLAT * scale || fabs(dh[18]) > CLOSED_FLAT * scale ||
        fabs(w->sa[1]) > CLOSED_FLAT || fabs(w->ca[0]) > CLOSED_FLAT)
        return -1;
    double r[3], p[3]; /* |p_xy|^2 at psi_3 = 0, pi/2, pi */
    for (int k = 0; k < 3; k++) {
        elbow_point(w, k * CLOSED_PI / 2, p);
        r[k] = p[0] * p[0] + p[1] * p[1];
    }
    d->E0 = 0.5 * (r[0] + r[2]);
    d->Ec = 0.5 * (r[0] - r[2]);
    d->Es = r[1] - d->E0;
    if (!(hypot(d->Ec, d->Es) > CLOSED_FLAT * scale * scale)) return -1; /* the elbow is not read from rho^2 */
    w->k.amp[0] = d->h = amplitude;
    apair_ik_wrist_slide1_position6_invariants(dh, w->inv_pos);
    return 0;
}

void apair_ik_wrist_slide1_solve1(const void *design, const double *Tt, double tol, double *qj, double *ej, int *found,
                                  int *candidates, int *flags)
{
    const wrist_slide1_design *d = (const wrist_slide1_design *)design;
    const wrist_design *w = &d->w;
    const double *dh = w->dh;
    double W[3], L[3], quad[3];
    *found = *candidates = *flags = 0;
    apair_ik_wrist_slide1_position6_core(w->inv_pos, dh, Tt, W, L, quad);
    double psi1s[CLOSED_ROOTS + 1];
    int n1 = closed_half_angles(2, quad, w->scale + sqrt(W[0] * W[0] + W[1] * W[1] + W[2] * W[2]), psi1s);
    if (n1 < 0) { *flags = -1; return; } /* the polynomial vanishes: not separated */
    double R6x[9], tiny = (CLOSED_FLAT * w->scale) * (CLOSED_FLAT * w->scale), K = hypot(d->Ec, d->Es);
    double beta = atan2(d->Es, d->Ec);
    tool_rotation(w, Tt, R6x);
    for (int k1 = 0; k1 < n1; k1++) {
        double psi1 = psi1s[k1], t1 = closed_wrap(psi1 - w->phi[0]);
        double theta1[2] = {t1, closed_wrap4(t1 - copysign(2 * CLOSED_PI, t1))};
        for (int j1 = 0; j1 < 2; j1++) {
            double A1[12], u[3];
            closed_dh4(dh[0], w->ca[0], w->sa[0], dh[2] + d->h * cos(0.5 * theta1[j1]), psi1, A1);
            for (int k = 0; k < 3; k++) /* W - O_1 in frame 1 */
                u[k] = A1[k] * (W[0] - A1[3]) + A1[4 + k] * (W[1] - A1[7]) + A1[8 + k] * (W[2] - A1[11]);
            double x = (u[0] * u[0] + u[1] * u[1] - d->E0) / K; /* cos(psi_3 - beta) */
            if (!(fabs(x) <= 1 + 1e-6)) continue;
            double rest = 1 - x * x, turn = rest <= 4 * CLOSED_DOUBLE ? 0.0 : acos(fmin(1.0, fmax(-1.0, x)));
            for (int e = 0; e < (turn > 0 ? 2 : 1); e++) {
                double psi3 = e ? beta - turn : beta + turn, p[3], psi2 = 0.0;
                elbow_point(w, psi3, p);
                if (p[0] * p[0] + p[1] * p[1] <= tiny) *flags |= 4; /* the wrist point on axis 2: psi_2 free */
                else psi2 = atan2(p[0] * u[1] - p[1] * u[0], p[0] * u[0] + p[1] * u[1]);
                /* (theta_1's twins are its two representatives already) */
                apair_wrist_keep(w, Tt, tol, R6x, A1, psi1, psi2, psi3, 0, theta1[j1], 0, qj, ej, found, candidates,
                                 flags);
            }
        }
    }
    closed_sort(qj, ej, *found);
}

int apair_ik_wrist_apair(const double *dh, const double *amplitude, double scale, size_t count, const double *target,
                         ptrdiff_t target_stride, double tol, double *q, double *error, int *found, int *candidates,
                         int *flags)
{
    apair_ik_closed solver;
    if (apair_ik_closed_init_apair(&solver, dh, amplitude, scale) ||
        (solver.family != APAIR_IK_WRIST_APAIR && solver.family != APAIR_IK_WRIST_SLIDES))
        return -1;
    return apair_ik_closed_solve(&solver, count, target, target_stride, tol, q, error, found, candidates, flags);
}

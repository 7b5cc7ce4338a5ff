/*
 * A copy of src/csrc/apair_ik6r.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik6r.c. Content hash: 1302ee710baa221b
 */
/*
 * The 6R elimination's back-substitution (apair.ik.elimination6r, derivations/chain_ik6r.py): the
 * six joint angles of each eigenpair of its companion matrix. Hand-written C: the C backend of
 * codegen copies it into generated/c, the library it belongs to. Declared in apair.h (template:
 * codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_internal.h"

/* The complex psi with (cos psi, sin psi) proportional to (c, s), and (cos psi, sin psi) = (c, s) / r with
 * r = sqrt(c^2 + s^2) (e^{i psi} = (c + i s) / r and e^{-i psi} = (c - i s) / r). */
static cplx angle_of(cplx c, cplx s, cplx *cs)
{
    cplx r = csqrt(c * c + s * s);
    cs[0] = c / r;
    cs[1] = s / r;
    return -I * clog((c + I * s) / r);
}

/* psi = sigma + 2 atan x and (cos psi, sin psi) from the half-angle tangent, without trigonometry of a
 * complex number: (cos, sin)(psi - sigma) = (1 - x^2, 2 x) / (1 + x^2), turned by sigma. */
static cplx half_angle(double sigma, cplx x, cplx *cs)
{
    cplx d = 1.0 + x * x, c0 = (1.0 - x * x) / d, s0 = 2.0 * x / d;
    double cg = cos(sigma), sg = sin(sigma);
    cs[0] = cg * c0 - sg * s0;
    cs[1] = sg * c0 + cg * s0;
    return sigma + 2.0 * catan(x);
}

int apair_ik6r_angles(size_t count, const double *x3, const double *vec, const double *P, const double *L,
                      const double *sigma, const double *dh, const double *T, double *theta)
{
    double ca[5], sa[5];
    for (int i = 0; i < 5; i++) { ca[i] = cos(dh[4 * i + 1]); sa[i] = sin(dh[4 * i + 1]); }
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
        cplx psi[6], cs[5][2], ext[3][3];
        psi[2] = half_angle(sigma[0], x, cs[2]);
        psi[3] = half_angle(sigma[1], n4 / d4, cs[3]);
        psi[4] = half_angle(sigma[2], n5 / d5, cs[4]);
        for (int k = 0; k < 3; k++) { ext[k][0] = 1.0; ext[k][1] = cs[2 + k][0]; ext[k][2] = cs[2 + k][1]; }
        /* X12 (without its constant) = L^T P (1, c3, s3) (x) (1, c4, s4) (x) (1, c5, s5) */
        cplx rhs[14], X12[8];
        for (int r = 0; r < 14; r++) {
            cplx acc = 0.0;
            for (int m = 0; m < 27; m++) acc += P[27 * r + m] * (ext[0][m / 9] * ext[1][(m / 3) % 3] * ext[2][m % 3]);
            rhs[r] = acc;
        }
        for (int c = 0; c < 8; c++) {
            cplx acc = 0.0;
            for (int r = 0; r < 14; r++) acc += rhs[r] * L[8 * r + c];
            X12[c] = acc;
        }
        /* X12 = (1, c1, s1) (x) (1, c2, s2) minus its constant: c2, s2 at 0, 1; c1, s1 at 2, 5 */
        psi[0] = angle_of(X12[2], X12[5], cs[0]);
        psi[1] = angle_of(X12[0], X12[1], cs[1]);
        /* psi6: A_6's first column (cos psi6, sin psi6, 0) = R_5^T ... R_1^T T e_x, R_i = Rz(psi_i) Rx(alpha_i) */
        cplx u0 = T[0], u1 = T[4], u2 = T[8], unused[2];
        for (int i = 0; i < 5; i++) {
            cplx c = cs[i][0], s = cs[i][1], t;
            t = c * u0 + s * u1; u1 = c * u1 - s * u0; u0 = t;
            t = ca[i] * u1 + sa[i] * u2; u2 = ca[i] * u2 - sa[i] * u1; u1 = t;
        }
        psi[5] = angle_of(u0, u1, unused);
        for (int i = 0; i < 6; i++) {
            cplx th = psi[i] - dh[4 * i + 3];
            theta[2 * (6 * j + i)] = creal(th);
            theta[2 * (6 * j + i) + 1] = cimag(th);
        }
    }
    return 0;
}

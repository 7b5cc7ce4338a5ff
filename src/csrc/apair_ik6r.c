/*
 * The 6R elimination (apair.ik.elimination6r, derivations/chain_ik6r.py): its back-substitution (the
 * six joint angles of each eigenpair of its companion matrix), the whole elimination of one pose with
 * the caller's LAPACK (apair_ik6r_eliminate, apair_ik6r_solve), and every real solution of a pose,
 * verified on fk (apair_ik6r, with the closed forms' polish of apair_ik_closed.h). Hand-written C: the C backend of
 * codegen copies it into generated/c, the library it belongs to. Declared in apair.h (template:
 * codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_closed.h"

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

/* ---- The whole elimination of one pose in C (apair.ik.elimination6r's eliminate, reversed_chain and
 * verified, step for step): the equations kernel, LAPACK's SVD, LU solve and eigenproblem (through the
 * caller's pointers: the library itself needs only libm), the back-substitution above, and Newton's
 * method with the checks that certify the 16 solutions. The constants are the module's. */

#define IK6R_COUNT 16           /* COUNT */
#define IK6R_RANK_TOL 1e-9     /* RANK_TOL */
#define IK6R_SPURIOUS_TOL 1e-3 /* SPURIOUS_TOL */
#define IK6R_NEWTON 8          /* NEWTON */
#define IK6R_STALL 0.25        /* STALL */
#define IK6R_CONVERGED 1e-8    /* CONVERGED */
#define IK6R_ACCURATE 1e-6     /* ACCURATE */
#define IK6R_IMAG_MAX 30.0     /* IMAG_MAX */
#define IK6R_SEPARATION 1e3    /* SEPARATION */
#define IK6R_SAME 1e-6         /* SAME */
#define IK6R_WORK 1024         /* doubles of LAPACK workspace: above what dgesdd (600) and dgeev (4 n = 96) need, under dgeev's blocked optimum (4283; n = 24 gains nothing from it) */

/* (1, cos psi, sin psi) (1 + x^2) on (1, x, x^2), x = tan((psi - sigma)/2): elimination6r.chart */
static void ik6r_chart(double sigma, double H[3][3])
{
    double c = cos(sigma), s = sin(sigma);
    H[0][0] = 1.0; H[0][1] = 0.0;      H[0][2] = 1.0;
    H[1][0] = c;   H[1][1] = -2.0 * s; H[1][2] = -c;
    H[2][0] = s;   H[2][1] = 2.0 * c;  H[2][2] = -s;
}

int apair_ik6r_eliminate(const apair_lapack *lapack, const double *dh, const double *T, const double *sigma,
                         double *theta)
{
    double P[14 * 27], Q[14 * 9];
    apair_ik6r_equations(dh, T, P, Q);
    for (int r = 0; r < 14; r++) P[27 * r] -= Q[9 * r];
    /* the SVD of Q's eight non-constant columns (column-major, as LAPACK takes them) */
    double A[14 * 8], sv[8], U[14 * 14], Vt[8 * 8], work[IK6R_WORK];
    int iwork[64], m = 14, n = 8, ldu = 14, ldvt = 8, lwork = IK6R_WORK, info = 0;
    for (int r = 0; r < 14; r++)
        for (int c = 0; c < 8; c++) A[r + 14 * c] = Q[9 * r + 1 + c];
    char all = 'A';
    lapack->dgesdd(&all, &m, &n, A, &m, sv, U, &ldu, Vt, &ldvt, work, &lwork, iwork, &info);
    if (info || !(sv[7] > IK6R_RANK_TOL * sv[0])) return 1; /* (NaN included) */
    /* N = U[:, 8:]^T P (6 x 27): six rows free of X12 */
    double Nm[6][27];
    for (int a = 0; a < 6; a++)
        for (int k = 0; k < 27; k++) {
            double acc = 0.0;
            for (int r = 0; r < 14; r++) acc += U[r + 14 * (8 + a)] * P[27 * r + k];
            Nm[a][k] = acc;
        }
    /* G[a][p][x4^i x5^j] = sum_{k, m} N[a][9 k + m] H3[k][p] H45[m][.]; M(x3) = sum_p x3^p M[p] (12 x 12),
     * row e * 6 + a is row a times x4^e, on the monomials x4^i x5^j (i <= 3, j <= 2) */
    double H3[3][3], H4[3][3], H5[3][3], G[6][3][9];
    ik6r_chart(sigma[0], H3);
    ik6r_chart(sigma[1], H4);
    ik6r_chart(sigma[2], H5);
    for (int a = 0; a < 6; a++)
        for (int p = 0; p < 3; p++)
            for (int nn = 0; nn < 9; nn++) {
                double acc = 0.0;
                for (int k = 0; k < 3; k++) {
                    if (H3[k][p] == 0.0) continue;
                    double inner = 0.0;
                    for (int mm = 0; mm < 9; mm++) inner += Nm[a][9 * k + mm] * H4[mm / 3][nn / 3] * H5[mm % 3][nn % 3];
                    acc += H3[k][p] * inner;
                }
                G[a][p][nn] = acc;
            }
    /* M2 X = [M0, M1] (column-major 12 x 12 and 12 x 24) */
    double M2[144], X[12 * 24];
    int ipiv[12], n12 = 12, nrhs = 24;
    memset(M2, 0, sizeof M2);
    memset(X, 0, sizeof X);
    for (int e = 0; e < 2; e++)
        for (int a = 0; a < 6; a++)
            for (int nn = 0; nn < 9; nn++) {
                int row = 6 * e + a, col = nn + 3 * e;
                M2[row + 12 * col] = G[a][2][nn];
                X[row + 12 * col] = G[a][0][nn];
                X[row + 12 * (12 + col)] = G[a][1][nn];
            }
    lapack->dgesv(&n12, &nrhs, M2, &n12, ipiv, X, &n12, &info);
    if (info) return 1; /* M2 singular */
    for (int k = 0; k < 12 * 24; k++)
        if (!isfinite(X[k])) return 1;
    /* the companion matrix [[0, I], [-X0, -X1]] and its eigenpairs */
    double K[24 * 24], wr[24], wi[24], vr[24 * 24], vl[1];
    int n24 = 24, one = 1;
    memset(K, 0, sizeof K);
    for (int i = 0; i < 12; i++) K[i + 24 * (i + 12)] = 1.0;
    for (int i = 0; i < 12; i++)
        for (int j = 0; j < 24; j++) K[12 + i + 24 * j] = -X[i + 12 * j];
    char no = 'N', yes = 'V';
    lapack->dgeev(&no, &yes, &n24, K, &n24, wr, wi, vl, &one, vr, &n24, work, &lwork, &info);
    if (info) return 1;
    /* the eight spurious eigenvalues: the eight nearest +-i, within SPURIOUS_TOL, four above the axis */
    double near[24];
    int order[24];
    for (int j = 0; j < 24; j++) {
        cplx x = wr[j] + I * wi[j];
        double up = cabs(x - I), down = cabs(x + I);
        near[j] = (up < down ? up : down) / (1.0 + cabs(x));
        if (!(near[j] == near[j])) return 1;
        order[j] = j;
    }
    for (int a = 1; a < 24; a++)
        for (int b = a; b > 0 && near[order[b]] < near[order[b - 1]]; b--) {
            int t = order[b]; order[b] = order[b - 1]; order[b - 1] = t;
        }
    int above = 0;
    for (int k = 0; k < 8; k++) {
        if (near[order[k]] > IK6R_SPURIOUS_TOL) return 1;
        above += wi[order[k]] > 0;
    }
    if (above != 4) return 1;
    /* the 16 others, with their complex eigenvectors (LAPACK's pairs: columns j, j + 1 = Re, Im) */
    double x3[2 * IK6R_COUNT], vec[2 * 24 * IK6R_COUNT];
    for (int k = 0; k < IK6R_COUNT; k++) {
        int j = order[8 + k];
        x3[2 * k] = wr[j];
        x3[2 * k + 1] = wi[j];
        int re = j, im = -1;
        double sign = 1.0;
        if (wi[j] > 0) im = j + 1;
        else if (wi[j] < 0) { re = j - 1; im = j; sign = -1.0; }
        for (int r = 0; r < 24; r++) {
            vec[2 * (24 * k + r)] = vr[r + 24 * re];
            vec[2 * (24 * k + r) + 1] = im < 0 ? 0.0 : sign * vr[r + 24 * im];
        }
    }
    /* L = (U[:, :8] / sv) Vt (14 x 8): X12 without its constant from the 14 equations */
    double L[14 * 8];
    for (int r = 0; r < 14; r++)
        for (int c = 0; c < 8; c++) {
            double acc = 0.0;
            for (int k = 0; k < 8; k++) acc += U[r + 14 * k] / sv[k] * Vt[k + 8 * c];
            L[8 * r + c] = acc;
        }
    return apair_ik6r_angles(IK6R_COUNT, x3, vec, P, L, sigma, dh, T, theta);
}

/* The chain read from its end (elimination6r.reversed_chain): dh' (6 x 4) and T' = Tx(a6) Rx(alpha6) T^-1 */
static void ik6r_reversed(const double *dh, const double *T, double *rdh, double *rT)
{
    for (int k = 0; k < 6; k++) {
        rdh[4 * k] = k < 5 ? -dh[4 * (4 - k)] : 0.0;
        rdh[4 * k + 1] = k < 5 ? -dh[4 * (4 - k) + 1] : 0.0;
        rdh[4 * k + 2] = -dh[4 * (5 - k) + 2];
        rdh[4 * k + 3] = 0.0;
    }
    double base[12], inv[12];
    closed_dh4(dh[20], cos(dh[21]), sin(dh[21]), 0.0, 0.0, base);
    closed_inv34(T, inv);
    closed_mul34(base, inv, rT);
    rT[12] = rT[13] = rT[14] = 0.0;
    rT[15] = 1.0;
}

/* The pose's coordinates (t, x) (7 complex) of the homotopy system: x the unit quaternion (w, x, y, z)
 * of T's rotation by Shepperd's branch (its sign does not matter to Newton's method) */
static void ik6r_target(const double *T, double *p)
{
    double r00 = T[0], r01 = T[1], r02 = T[2], r10 = T[4], r11 = T[5], r12 = T[6], r20 = T[8], r21 = T[9], r22 = T[10];
    double d[4] = {1 + r00 + r11 + r22, 1 + r00 - r11 - r22, 1 - r00 + r11 - r22, 1 - r00 - r11 + r22}, x[4];
    int k = 0;
    for (int j = 1; j < 4; j++)
        if (d[j] > d[k]) k = j;
    if (k == 0) { x[0] = d[0]; x[1] = r21 - r12; x[2] = r02 - r20; x[3] = r10 - r01; }
    else if (k == 1) { x[0] = r21 - r12; x[1] = d[1]; x[2] = r01 + r10; x[3] = r02 + r20; }
    else if (k == 2) { x[0] = r02 - r20; x[1] = r01 + r10; x[2] = d[2]; x[3] = r12 + r21; }
    else { x[0] = r10 - r01; x[1] = r02 + r20; x[2] = r12 + r21; x[3] = d[3]; }
    double norm = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
    for (int j = 0; j < 14; j++) p[j] = 0.0;
    for (int j = 0; j < 3; j++) p[2 * j] = T[4 * j + 3];
    for (int j = 0; j < 4; j++) p[2 * (3 + j)] = x[j] / norm;
}

int apair_ik6r_solve(const apair_lapack *lapack, const apair_ik_problem *pb, const double *T, const double *sigma,
                     double *theta)
{
    if (!lapack || !pb || pb->n != 6) return -1;
    for (int i = 0; i < 6; i++)
        if (pb->kind[i] != 0) return -1;
    const double *dh = pb->dh;
    if (apair_ik6r_eliminate(lapack, dh, T, sigma, theta)) { /* e.g. axes 1 and 2 parallel: from the end */
        double rdh[24], rT[16], psi[2 * 6 * IK6R_COUNT];
        ik6r_reversed(dh, T, rdh, rT);
        if (apair_ik6r_eliminate(lapack, rdh, rT, sigma, psi)) return 1;
        for (int j = 0; j < IK6R_COUNT; j++)
            for (int i = 0; i < 6; i++) { /* theta_i = -psi'_{5-i} - phi_i */
                theta[2 * (6 * j + i)] = -psi[2 * (6 * j + 5 - i)] - dh[4 * i + 3];
                theta[2 * (6 * j + i) + 1] = -psi[2 * (6 * j + 5 - i) + 1];
            }
    }
    /* verified: every candidate within IMAG_MAX, Newton-converged, and the converged ones distinct */
    for (int k = 0; k < 6 * IK6R_COUNT; k++)
        if (!(fabs(theta[2 * k + 1]) <= IK6R_IMAG_MAX)) return 1;
    double p[14], size[IK6R_COUNT], worst = 0.0;
    ik6r_target(T, p);
    if (apair_ik_newton(pb, p, IK6R_COUNT, theta, IK6R_NEWTON, IK6R_CONVERGED, IK6R_ACCURATE, IK6R_STALL,
                        IK6R_IMAG_MAX, size))
        return -1;
    for (int j = 0; j < IK6R_COUNT; j++) {
        if (!(size[j] <= IK6R_ACCURATE)) return 1;
        if (size[j] > worst) worst = size[j];
    }
    /* |e^{i theta} - e^{i theta'}| over the mean modulus: |theta - theta'| (mod 2 pi) to first order */
    cplx z[IK6R_COUNT][6];
    double mod[IK6R_COUNT][6], need = IK6R_SEPARATION * worst > IK6R_SAME ? IK6R_SEPARATION * worst : IK6R_SAME;
    for (int j = 0; j < IK6R_COUNT; j++)
        for (int i = 0; i < 6; i++) {
            z[j][i] = cexp(I * (theta[2 * (6 * j + i)] + I * theta[2 * (6 * j + i) + 1]));
            mod[j][i] = cabs(z[j][i]);
        }
    for (int j = 0; j < IK6R_COUNT; j++)
        for (int l = j + 1; l < IK6R_COUNT; l++) {
            double gap = 0.0;
            for (int i = 0; i < 6; i++) {
                double g = cabs(z[j][i] - z[l][i]) / (0.5 * (mod[j][i] + mod[l][i]));
                if (!(g <= gap)) gap = g;
            }
            if (!(gap > need)) return 1;
        }
    return 0;
}

#define IK6R_REAL 1e-5 /* |Im theta| under which a solution is a real candidate (apair.ik.homotopy.problem.REAL) */

static const double ik6r_sigma[3] = {0.4142, -0.7071, 0.5773}; /* the charts' turns: elimination6r.SIGMA */

int apair_ik6r(const apair_lapack *lapack, const double *dh, double scale, const double *T, double tol, double *q,
               double *error, int *found, int *candidates)
{
    *found = *candidates = 0;
    if (!lapack || !dh || !T || !(scale > 0) || !isfinite(scale) || !(tol > 0)) return -1;
    /* the chain and the pose in units of the scale (as apair.ik.solver's _UnitDesign) */
    double udh[24], Tu[16], pair[12] = {0}, theta[2 * 6 * IK6R_COUNT];
    int kind[6] = {0};
    for (int i = 0; i < 6; i++) {
        udh[4 * i] = dh[4 * i] / scale;
        udh[4 * i + 1] = dh[4 * i + 1];
        udh[4 * i + 2] = dh[4 * i + 2] / scale;
        udh[4 * i + 3] = dh[4 * i + 3];
    }
    memcpy(Tu, T, sizeof Tu);
    for (int r = 0; r < 3; r++) Tu[4 * r + 3] /= scale;
    apair_ik_problem pb = {6, kind, pair, udh};
    int rc = apair_ik6r_solve(lapack, &pb, Tu, ik6r_sigma, theta);
    if (rc) return rc;
    closed_fk k;
    if (closed_fk_init(&k, udh)) return -1;
    for (int j = 0; j < IK6R_COUNT; j++) {
        double x[6];
        int real = 1;
        for (int i = 0; i < 6; i++) {
            real &= fabs(theta[2 * (6 * j + i) + 1]) <= IK6R_REAL;
            x[i] = closed_wrap(theta[2 * (6 * j + i)]);
        }
        if (!real) continue;
        (*candidates)++;
        double err = closed_polish(&k, udh, 1.0, Tu, tol, x); /* translations in units of the scale */
        if (!(err <= tol)) continue;
        for (int i = 0; i < 6; i++) x[i] = closed_wrap(x[i]);
        closed_keep_at_most(q, error, found, x, err, IK6R_COUNT);
    }
    closed_sort(q, error, *found);
    return 0;
}

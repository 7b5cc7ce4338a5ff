/*
 * A copy of src/csrc/apair_ik4.c (hand-written), made by codegen/backends/c for the library in
 * generated/c. Do not edit: edit src/csrc/apair_ik4.c. Content hash: 77e9cfe801fbcdf3
 */
/*
 * The 4-joint elimination's steps in C (apair.ik.elimination4, apair.ik.pencil): the polynomial
 * pencil of two quadrics' images and its companion matrix (apair_ik4_pencil), the screening of its
 * eigenvalues on the Sylvester matrices (apair_ik4_screen) and the left half's joints
 * (apair_ik4_left). Hand-written C: the C backend of codegen copies it into generated/c, the
 * library it belongs to. Declared in apair.h (template: codegen/backends/c/templates/apair.h.j2).
 */
#include "apair_ik_internal.h"

#define IK4_DEG 16   /* the largest degree of an image Q(W(u3, u4)) in u3 or u4 (two A-pairs: 8) */
#define IK4_N 32     /* the largest Sylvester size in u4 */

/* Solves A X = B for complex A and B (see GAUSS_SOLVE). */
GAUSS_SOLVE(csolve_m, cplx, cabs)

/* Solves A x = b (n x n, row-major, overwritten); b becomes x. */
static int csolve(int n, cplx *A, cplx *b) { return csolve_m(n, A, 1, b); }

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

/* Dense linear algebra of the native FMU; see linalg.h. */
#include "linalg.h"

#include <math.h>
#include <string.h>

static int all_finite(const double *a, size_t count)
{
    for (size_t i = 0; i < count; ++i)
        if (!isfinite(a[i])) return 0;
    return 1;
}

void lcv_matmul(const double *A, int lda, const double *B, int ldb, double *C, int ldc, int r, int k, int c)
{
    for (int i = 0; i < r; ++i) {
        double *Ci = C + (size_t)i * ldc;
        for (int j = 0; j < c; ++j) Ci[j] = 0.0;
        for (int l = 0; l < k; ++l) {
            double a = A[(size_t)i * lda + l];
            if (a == 0.0) continue;
            const double *Bl = B + (size_t)l * ldb;
            for (int j = 0; j < c; ++j) Ci[j] += a * Bl[j];
        }
    }
}

int lcv_solve(double *A, int n, double *B, int ldb, int nrhs)
{
    for (int k = 0; k < n; ++k) {
        int piv = k;
        double best = fabs(A[(size_t)k * n + k]);
        for (int i = k + 1; i < n; ++i) {
            double v = fabs(A[(size_t)i * n + k]);
            if (v > best) { best = v; piv = i; }
        }
        if (best == 0.0 || !isfinite(best)) return -1;
        if (piv != k) {
            for (int j = 0; j < n; ++j) {
                double t = A[(size_t)k * n + j]; A[(size_t)k * n + j] = A[(size_t)piv * n + j]; A[(size_t)piv * n + j] = t;
            }
            for (int j = 0; j < nrhs; ++j) {
                double t = B[(size_t)k * ldb + j]; B[(size_t)k * ldb + j] = B[(size_t)piv * ldb + j];
                B[(size_t)piv * ldb + j] = t;
            }
        }
        for (int i = k + 1; i < n; ++i) {
            double f = A[(size_t)i * n + k] / A[(size_t)k * n + k];
            if (f == 0.0) continue;
            for (int j = k + 1; j < n; ++j) A[(size_t)i * n + j] -= f * A[(size_t)k * n + j];
            for (int j = 0; j < nrhs; ++j) B[(size_t)i * ldb + j] -= f * B[(size_t)k * ldb + j];
        }
    }
    for (int k = n - 1; k >= 0; --k) {
        for (int j = 0; j < nrhs; ++j) {
            double v = B[(size_t)k * ldb + j];
            for (int l = k + 1; l < n; ++l) v -= A[(size_t)k * n + l] * B[(size_t)l * ldb + j];
            B[(size_t)k * ldb + j] = v / A[(size_t)k * n + k];
        }
    }
    for (int i = 0; i < n; ++i)
        if (!all_finite(B + (size_t)i * ldb, (size_t)nrhs)) return -1;
    return 0;
}

int lcv_solve_scaled(const double *M, int n, double *B, int ldb, int nrhs, double *work)
{
    double *d = work + (size_t)n * (size_t)n;
    for (int i = 0; i < n; ++i) {
        double diag = fabs(M[(size_t)i * n + i]), row = 0.0;
        for (int j = 0; j < n; ++j) if (fabs(M[(size_t)i * n + j]) > row) row = fabs(M[(size_t)i * n + j]);
        double base = diag > 0 ? diag : (row > 0 ? row : 1.0);
        if (!isfinite(base)) return -1;
        d[i] = exp2(-nearbyint(0.5 * log2(base)));   /* a power of two: the scaling is exact */
    }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) work[(size_t)i * n + j] = d[i] * M[(size_t)i * n + j] * d[j];
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < nrhs; ++j) B[(size_t)i * ldb + j] *= d[i];
    if (lcv_solve(work, n, B, ldb, nrhs) != 0) return -1;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < nrhs; ++j) B[(size_t)i * ldb + j] *= d[i];
    return 0;
}

static double norm1(const double *A, int n)
{
    double best = 0.0;
    for (int j = 0; j < n; ++j) {
        double s = 0.0;
        for (int i = 0; i < n; ++i) s += fabs(A[(size_t)i * n + j]);
        if (s > best) best = s;
    }
    return best;
}

/* ell(A, m) of Al-Mohy and Higham (2009): extra squarings that keep the backward error of
   the degree-m Pade approximant at unit roundoff; ||abs(A)^(2m+1)||_1 exactly (r |A| products) */
static int ell(const double *A, int n, int m, double *r, double *t)
{
    double c;
    switch (m) {
    case 3: c = 100800.; break;
    case 5: c = 10059033600.; break;
    case 7: c = 4487938430976000.; break;
    case 9: c = 5914384781877411840000.; break;
    default: c = 113250775606021113483283660800000000.; break;
    }
    double nrm = norm1(A, n);
    if (nrm == 0.0) return 0;
    for (int j = 0; j < n; ++j) r[j] = 1.0;
    for (int k = 0; k < 2 * m + 1; ++k) {
        for (int j = 0; j < n; ++j) {
            double v = 0.0;
            for (int i = 0; i < n; ++i) v += r[i] * fabs(A[(size_t)i * n + j]);
            t[j] = v;
        }
        memcpy(r, t, sizeof(double) * (size_t)n);
    }
    double abs_pow = 0.0;
    for (int j = 0; j < n; ++j) if (r[j] > abs_pow) abs_pow = r[j];
    if (abs_pow == 0.0) return 0;
    if (!isfinite(abs_pow)) return 64;
    double alpha = abs_pow / (nrm * c);
    int value = (int)ceil(log2(alpha / ldexp(1.0, -53)) / (2 * m));
    return value > 0 ? value : 0;
}

size_t lcv_expm_work(int n) { return 9 * (size_t)n * (size_t)n + 2 * (size_t)n; }

int lcv_expm(const double *Ain, int n, double *E, double *work)
{
    static const double theta13 = 5.371920351148152e0;
    static const double b3[4] = {120., 60., 12., 1.};
    static const double b5[6] = {30240., 15120., 3360., 420., 30., 1.};
    static const double b7[8] = {17297280., 8648640., 1995840., 277200., 25200., 1512., 56., 1.};
    static const double b9[10] = {17643225600., 8821612800., 2075673600., 302702400., 30270240., 2162160.,
                                  110880., 3960., 90., 1.};
    static const double b13[14] = {64764752532480000., 32382376266240000., 7771770303897600.,
                                   1187353796428800., 129060195264000., 10559470521600., 670442572800.,
                                   33522128640., 1323241920., 40840800., 960960., 16380., 182., 1.};
    size_t nn = (size_t)n * (size_t)n;
    double *A = work, *A2 = A + nn, *A4 = A2 + nn, *A6 = A4 + nn, *U = A6 + nn, *V = U + nn, *T = V + nn,
           *P = T + nn, *Pk = P + nn, *r = Pk + nn, *t = r + n;
    int s = 0, m;
    const double *b;

    if (!all_finite(Ain, nn)) return -1;
    memcpy(A, Ain, sizeof(double) * nn);
    lcv_matmul(A, n, A, n, A2, n, n, n, n);
    lcv_matmul(A2, n, A2, n, A4, n, n, n, n);
    lcv_matmul(A4, n, A2, n, A6, n, n, n, n);
    if (!all_finite(A6, nn)) return -1;
    double d4 = pow(norm1(A4, n), 0.25), d6 = pow(norm1(A6, n), 1.0 / 6.0), d8 = 0.0;
    double eta1 = d4 > d6 ? d4 : d6;
    if (eta1 <= 1.495585217958292e-2 && ell(A, n, 3, r, t) == 0) { m = 3; b = b3; }
    else if (eta1 <= 2.539398330063230e-1 && ell(A, n, 5, r, t) == 0) { m = 5; b = b5; }
    else {
        lcv_matmul(A4, n, A4, n, P, n, n, n, n);
        d8 = pow(norm1(P, n), 0.125);
        double eta3 = d6 > d8 ? d6 : d8;
        if (eta3 <= 9.504178996162932e-1 && ell(A, n, 7, r, t) == 0) { m = 7; b = b7; }
        else if (eta3 <= 2.097847961257068e0 && ell(A, n, 9, r, t) == 0) { m = 9; b = b9; }
        else {
            lcv_matmul(A4, n, A6, n, P, n, n, n, n);
            double d10 = pow(norm1(P, n), 0.1);
            double eta4 = d8 > d10 ? d8 : d10;
            double eta5 = eta3 < eta4 ? eta3 : eta4;
            s = eta5 > 0 ? (int)ceil(log2(eta5 / theta13)) : 0;
            if (s < 0) s = 0;
            if (s > 1000) return -1;
            double f = ldexp(1.0, -s);
            for (size_t i = 0; i < nn; ++i) P[i] = A[i] * f;
            s += ell(P, n, 13, r, t);
            if (s > 1000) return -1;
            m = 13; b = b13;
            if (s > 0) {
                f = ldexp(1.0, -s);
                double f2 = f * f;
                for (size_t i = 0; i < nn; ++i) { A[i] *= f; A2[i] *= f2; A4[i] *= f2 * f2; A6[i] *= f2 * f2 * f2; }
            }
        }
    }
    if (m <= 9) {
        /* U = A (b[1] I + b[3] A^2 + ...), V = b[0] I + b[2] A^2 + ... */
        for (size_t i = 0; i < nn; ++i) { T[i] = 0.0; V[i] = 0.0; }
        for (int i = 0; i < n; ++i) { T[(size_t)i * n + i] = b[1]; V[(size_t)i * n + i] = b[0]; }
        memcpy(Pk, A2, sizeof(double) * nn);          /* A^2, A^4, ... */
        for (int k = 2; k <= m - 1; k += 2) {
            for (size_t i = 0; i < nn; ++i) { T[i] += b[k + 1] * Pk[i]; V[i] += b[k] * Pk[i]; }
            if (k + 2 <= m - 1) {
                lcv_matmul(Pk, n, A2, n, P, n, n, n, n);
                memcpy(Pk, P, sizeof(double) * nn);
            }
        }
        lcv_matmul(A, n, T, n, U, n, n, n, n);
    } else {
        for (size_t i = 0; i < nn; ++i) T[i] = b[13] * A6[i] + b[11] * A4[i] + b[9] * A2[i];
        lcv_matmul(A6, n, T, n, P, n, n, n, n);
        for (size_t i = 0; i < nn; ++i) P[i] += b[7] * A6[i] + b[5] * A4[i] + b[3] * A2[i];
        for (int i = 0; i < n; ++i) P[(size_t)i * n + i] += b[1];
        lcv_matmul(A, n, P, n, U, n, n, n, n);
        for (size_t i = 0; i < nn; ++i) T[i] = b[12] * A6[i] + b[10] * A4[i] + b[8] * A2[i];
        lcv_matmul(A6, n, T, n, V, n, n, n, n);
        for (size_t i = 0; i < nn; ++i) V[i] += b[6] * A6[i] + b[4] * A4[i] + b[2] * A2[i];
        for (int i = 0; i < n; ++i) V[(size_t)i * n + i] += b[0];
    }
    /* (V - U) E = (V + U) */
    for (size_t i = 0; i < nn; ++i) { P[i] = V[i] - U[i]; E[i] = V[i] + U[i]; }
    if (lcv_solve(P, n, E, n, n) != 0) return -1;
    for (int k = 0; k < s; ++k) {
        lcv_matmul(E, n, E, n, T, n, n, n, n);
        memcpy(E, T, sizeof(double) * nn);
        if (!all_finite(E, nn)) return -1;
    }
    return all_finite(E, nn) ? 0 : -1;
}

#define AX(i, j) a[((size_t)(i) - 1) * (size_t)n + ((size_t)(j) - 1)]   /* 1-based access */
int lcv_eigenvalues(double *a, int n, double *wr, double *wi)
{
    if (!all_finite(a, (size_t)n * (size_t)n)) return -1;
    /* balance: at most 64 sweeps; each scaling factor is a power of two within [2^-64, 2^64] */
    const double radix = 2.0, sqrdx = 4.0;
    int done = 0;
    for (int sweep = 0; !done && sweep < 64; ++sweep) {
        done = 1;
        for (int i = 1; i <= n; ++i) {
            double r = 0.0, c = 0.0;
            for (int j = 1; j <= n; ++j)
                if (j != i) { c += fabs(AX(j, i)); r += fabs(AX(i, j)); }
            if (c != 0.0 && r != 0.0 && isfinite(c) && isfinite(r)) {
                double g = r / radix, f = 1.0, s = c + r;
                for (int k = 0; c < g && k < 64; ++k) { f *= radix; c *= sqrdx; }
                g = r * radix;
                for (int k = 0; c > g && k < 64; ++k) { f /= radix; c /= sqrdx; }
                if ((c + r) / f < 0.95 * s) {
                    done = 0;
                    g = 1.0 / f;
                    for (int j = 1; j <= n; ++j) AX(i, j) *= g;
                    for (int j = 1; j <= n; ++j) AX(j, i) *= f;
                }
            }
        }
    }
    if (!all_finite(a, (size_t)n * (size_t)n)) return -1;
    /* Hessenberg */
    for (int m = 2; m < n; ++m) {
        double x = 0.0;
        int i = m;
        for (int j = m; j <= n; ++j)
            if (fabs(AX(j, m - 1)) > fabs(x)) { x = AX(j, m - 1); i = j; }
        if (i != m) {
            for (int j = m - 1; j <= n; ++j) { double t = AX(i, j); AX(i, j) = AX(m, j); AX(m, j) = t; }
            for (int j = 1; j <= n; ++j) { double t = AX(j, i); AX(j, i) = AX(j, m); AX(j, m) = t; }
        }
        if (x != 0.0) {
            for (i = m + 1; i <= n; ++i) {
                double y = AX(i, m - 1);
                if (y != 0.0) {
                    y /= x;
                    AX(i, m - 1) = y;
                    for (int j = m; j <= n; ++j) AX(i, j) -= y * AX(m, j);
                    for (int j = 1; j <= n; ++j) AX(j, m) += y * AX(j, i);
                }
            }
        }
    }
    for (int i = 1; i <= n; ++i)
        for (int j = 1; j < i - 1; ++j) AX(i, j) = 0.0;
    /* shifted QR, at most 60 iterations per eigenvalue */
    int nn, m, l, its, mmin;
    double z = 0.0, y, x, w, v, u, t, s, r = 0.0, q = 0.0, p = 0.0, anorm = 0.0;
    for (int i = 1; i <= n; ++i)
        for (int j = (i - 1 > 1 ? i - 1 : 1); j <= n; ++j) anorm += fabs(AX(i, j));
    nn = n;
    t = 0.0;
    while (nn >= 1) {
        its = 0;
        do {
            for (l = nn; l >= 2; l--) {
                s = fabs(AX(l - 1, l - 1)) + fabs(AX(l, l));
                if (s == 0.0) s = anorm;
                if (fabs(AX(l, l - 1)) + s == s) { AX(l, l - 1) = 0.0; break; }
            }
            x = AX(nn, nn);
            if (l == nn) {
                wr[nn - 1] = x + t;
                wi[nn - 1] = 0.0;
                nn--;
            } else {
                y = AX(nn - 1, nn - 1);
                w = AX(nn, nn - 1) * AX(nn - 1, nn);
                if (l == nn - 1) {
                    p = 0.5 * (y - x);
                    q = p * p + w;
                    z = sqrt(fabs(q));
                    x += t;
                    if (q >= 0.0) {
                        z = p + (p >= 0.0 ? fabs(z) : -fabs(z));
                        wr[nn - 2] = wr[nn - 1] = x + z;
                        if (z != 0.0) wr[nn - 1] = x - w / z;
                        wi[nn - 2] = wi[nn - 1] = 0.0;
                    } else {
                        wr[nn - 2] = wr[nn - 1] = x + p;
                        wi[nn - 2] = z;
                        wi[nn - 1] = -z;
                    }
                    nn -= 2;
                } else {
                    if (its == 60) return -1;
                    if (its == 10 || its == 20) {
                        t += x;
                        for (int i = 1; i <= nn; ++i) AX(i, i) -= x;
                        s = fabs(AX(nn, nn - 1)) + fabs(AX(nn - 1, nn - 2));
                        y = x = 0.75 * s;
                        w = -0.4375 * s * s;
                    }
                    ++its;
                    for (m = nn - 2; m >= l; m--) {
                        z = AX(m, m);
                        r = x - z;
                        s = y - z;
                        p = (r * s - w) / AX(m + 1, m) + AX(m, m + 1);
                        q = AX(m + 1, m + 1) - z - r - s;
                        r = AX(m + 2, m + 1);
                        s = fabs(p) + fabs(q) + fabs(r);
                        p /= s;
                        q /= s;
                        r /= s;
                        if (m == l) break;
                        u = fabs(AX(m, m - 1)) * (fabs(q) + fabs(r));
                        v = fabs(p) * (fabs(AX(m - 1, m - 1)) + fabs(z) + fabs(AX(m + 1, m + 1)));
                        if (u + v == v) break;
                    }
                    for (int i = m + 2; i <= nn; ++i) {
                        AX(i, i - 2) = 0.0;
                        if (i != m + 2) AX(i, i - 3) = 0.0;
                    }
                    for (int k = m; k <= nn - 1; ++k) {
                        if (k != m) {
                            p = AX(k, k - 1);
                            q = AX(k + 1, k - 1);
                            r = 0.0;
                            if (k != nn - 1) r = AX(k + 2, k - 1);
                            if ((x = fabs(p) + fabs(q) + fabs(r)) != 0.0) {
                                p /= x;
                                q /= x;
                                r /= x;
                            }
                        }
                        s = sqrt(p * p + q * q + r * r);
                        if (p < 0.0) s = -s;
                        if (s != 0.0) {
                            if (k == m) {
                                if (l != m) AX(k, k - 1) = -AX(k, k - 1);
                            } else {
                                AX(k, k - 1) = -s * x;
                            }
                            p += s;
                            x = p / s;
                            y = q / s;
                            z = r / s;
                            q /= p;
                            r /= p;
                            for (int j = k; j <= nn; ++j) {
                                p = AX(k, j) + q * AX(k + 1, j);
                                if (k != nn - 1) {
                                    p += r * AX(k + 2, j);
                                    AX(k + 2, j) -= p * z;
                                }
                                AX(k + 1, j) -= p * y;
                                AX(k, j) -= p * x;
                            }
                            mmin = nn < k + 3 ? nn : k + 3;
                            for (int i = l; i <= mmin; ++i) {
                                p = x * AX(i, k) + y * AX(i, k + 1);
                                if (k != nn - 1) {
                                    p += z * AX(i, k + 2);
                                    AX(i, k + 2) -= p * r;
                                }
                                AX(i, k + 1) -= p * q;
                                AX(i, k) -= p;
                            }
                        }
                    }
                }
            }
        } while (l < nn - 1);
    }
    for (int i = 0; i < n; ++i)
        if (!isfinite(wr[i]) || !isfinite(wi[i])) return -1;
    return 0;
}
#undef AX

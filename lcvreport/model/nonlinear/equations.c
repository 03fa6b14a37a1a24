/* The nonlinear planar model's equations of motion, compiled (lcvreport/model/nonlinear/native.py).
 *
 * The same arithmetic as NonlinearModel._solve (model.py), one state (row) at a time: the
 * kinematics, the partial velocities W, the mass matrix, the axles' slips, the drive force D by
 * fixed-point iteration from 0 with the friction ellipse, the tire law (linear or brush), the
 * generalized accelerations.  A row's numbers depend on that row alone, so a variant gives the
 * same numbers alone and in a batch.  Tested against the numpy equations (tests/test_native.py).
 *
 * Compiled with -O2 -ffp-contract=off (no fused multiply-adds: the rounding of the source).
 */
#include <math.h>
#include <string.h>

#define NMAX 16   /* units */
#define AMAX 64   /* axles */
#define ZMAX (NMAX + 2)

/* the model: constants of one geometry */
typedef struct {
    int N, na, linear, iterations;
    double mu, drive_tires, rtol;
    const double *c;            /* N x N coupling offsets c_ik */
    const long long *au;        /* na: the axle's unit */
    const double *x, *tires, *steered, *driven, *drive_share;   /* na */
} Model;

/* per-row parameters (each B x N or B x na, row-major) */
typedef struct {
    const double *m, *I, *CF, *CM, *CSD2, *Fz, *muFz;
} Params;

/* the failure of a row: a driven axle out of friction */
typedef struct {
    long long row, axle;
    double needed, available;
} Failure;

static void brush(double t, double CF, double CM, double Fz, double mu_y, double *F, double *M)
{
    double cap = mu_y * Fz;
    double theta = CF * fabs(t) / (3.0 * (cap > 0 ? cap : INFINITY));
    int sliding = theta >= 1.0;
    double th = theta < 1.0 ? theta : 1.0;
    double sg = (t > 0) - (t < 0);
    double one_th = 1.0 - th;
    *F = -sg * cap * (sliding ? 1.0 : 3.0 * th - 3.0 * (th * th) + th * th * th);
    *M = sliding ? 0.0 : CM * t * (one_th * one_th * one_th);
}

/* LU with partial pivoting of the n x n matrix A (in place), pivots in piv */
static void lu(int n, double A[ZMAX][ZMAX], int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i][k]) > fabs(A[p][k])) p = i;
        piv[k] = p;
        if (p != k)
            for (int j = 0; j < n; j++) { double t = A[k][j]; A[k][j] = A[p][j]; A[p][j] = t; }
        for (int i = k + 1; i < n; i++) {
            A[i][k] /= A[k][k];
            for (int j = k + 1; j < n; j++) A[i][j] -= A[i][k] * A[k][j];
        }
    }
}

static void lu_solve(int n, double A[ZMAX][ZMAX], const int *piv, double *b)
{
    for (int k = 0; k < n; k++) {
        int p = piv[k];
        if (p != k) { double t = b[k]; b[k] = b[p]; b[p] = t; }
    }
    for (int i = 1; i < n; i++)
        for (int j = 0; j < i; j++) b[i] -= A[i][j] * b[j];
    for (int i = n - 1; i >= 0; i--) {
        for (int j = i + 1; j < n; j++) b[i] -= A[i][j] * b[j];
        b[i] /= A[i][i];
    }
}

/* x' of B states: x (B x (2N+3)), w (B x (3 na + 2)), U the held speed, s the tire scale; dx out,
 * D out (the drive force), forces out (B x 2 na: each axle's F_x then F_y in the wheel's axes, or
 * NULL).  Returns 0, or 1 with *fail filled (the first row that failed). */
int lcv_nonlinear_derivatives(const Model *md, const Params *pp, long long B, const double *xs, const double *ws,
                              double U, double s, double *dxs, double *Ds, double *forces, Failure *fail)
{
    const int N = md->N, na = md->na, nz = N + 2, nx = 2 * N + 3, nw = 3 * na + 2;
    for (long long b = 0; b < B; b++) {
        const double *x = xs + b * nx, *w = ws + b * nw;
        const double *m = pp->m + b * N, *I = pp->I + b * N;
        const double *CF = pp->CF + b * na, *CM = pp->CM + b * na, *CSD2 = pp->CSD2 + b * na;
        const double *Fz = pp->Fz + b * na, *muFz = pp->muFz + b * na;
        double *dx = dxs + b * nx;
        double e[NMAX][2], n[NMAX][2], V[NMAX][2], ub[NMAX], vb[NMAX], W[NMAX][ZMAX][2], bias[NMAX][2];
        const double v1 = x[2 + N], *r = x + 3 + N;
        for (int i = 0; i < N; i++) {
            double c = cos(x[2 + i]), sn = sin(x[2 + i]);
            e[i][0] = c; e[i][1] = sn; n[i][0] = -sn; n[i][1] = c;
        }
        for (int i = 0; i < N; i++) {
            for (int q = 0; q < 2; q++) {
                double acc = 0.0, acc2 = 0.0;
                for (int k = 0; k < N; k++) {
                    acc += md->c[i * N + k] * r[k] * n[k][q];
                    acc2 += md->c[i * N + k] * (r[k] * r[k]) * e[k][q];
                }
                V[i][q] = (U * e[0][q] + v1 * n[0][q]) + acc;
                bias[i][q] = ((U * r[0]) * n[0][q] - (v1 * r[0]) * e[0][q]) - acc2;
                W[i][0][q] = e[0][q];
                W[i][1][q] = n[0][q];
                for (int k = 0; k < N; k++) W[i][2 + k][q] = md->c[i * N + k] * n[k][q];
            }
            ub[i] = V[i][0] * e[i][0] + V[i][1] * e[i][1];
            vb[i] = V[i][0] * n[i][0] + V[i][1] * n[i][1];
        }
        /* the mass matrix, the inertial generalized forces */
        double M[ZMAX][ZMAX], Mr[ZMAX][ZMAX], inertial[ZMAX];
        for (int z = 0; z < nz; z++) {
            for (int y = 0; y < nz; y++) {
                double acc = 0.0;
                for (int i = 0; i < N; i++) acc += m[i] * (W[i][z][0] * W[i][y][0] + W[i][z][1] * W[i][y][1]);
                M[z][y] = acc;
            }
        }
        for (int i = 0; i < N; i++) M[2 + i][2 + i] += I[i];
        const double a_c = w[3 * na + 1];
        for (int z = 0; z < nz; z++) {
            double acc = 0.0;
            for (int i = 0; i < N; i++) {
                double ext0 = -m[i] * bias[i][0], ext1 = m[i] * a_c - m[i] * bias[i][1];
                acc += W[i][z][0] * ext0 + W[i][z][1] * ext1;
            }
            inertial[z] = acc;
        }
        for (int z = 1; z < nz; z++)
            for (int y = 1; y < nz; y++) Mr[z - 1][y - 1] = M[z][y];
        int piv[ZMAX];
        lu(N + 1, Mr, piv);
        /* the axles' slips */
        double tan_a[AMAX], cd[AMAX], sd[AMAX], Mz0[AMAX], dcos_sum = 0.0;
        int driven_turned = 0;
        const double delta = w[0];
        for (int j = 0; j < na; j++) {
            int i = (int)md->au[j];
            double ua = ub[i], ra = r[i], va = vb[i] + md->x[j] * ra;
            double d = delta * md->steered[j] + w[1 + 2 * na + j];
            cd[j] = cos(d); sd[j] = sin(d);
            double uw = ua * cd[j] + va * sd[j], vw = -ua * sd[j] + va * cd[j];
            tan_a[j] = vw / fabs(uw);
            Mz0[j] = w[1 + na + j] - s * CSD2[j] * ra / ua;
            dcos_sum += md->drive_share[j] * cd[j];
            if (d * md->driven[j] != 0.0) driven_turned = 1;
        }
        const int decoupled = md->linear && !driven_turned;
        double D = 0.0, zr[ZMAX];
        for (int it = 0; it < md->iterations; it++) {
            double F[NMAX][2], rhs[ZMAX];
            memset(F, 0, sizeof F);
            memcpy(rhs, inertial, sizeof(double) * nz);
            double mom[NMAX];
            memset(mom, 0, sizeof mom);
            for (int j = 0; j < na; j++) {
                double fx = md->driven[j] * (D / md->drive_tires), fy, mz;
                if (md->linear) {
                    fy = -s * CF[j] * tan_a[j];
                    mz = s * CM[j] * tan_a[j];
                } else {
                    double ratio = fx / muFz[j];
                    if (fabs(ratio) >= 1.0) {
                        fail->row = b; fail->axle = j; fail->needed = fabs(fx); fail->available = muFz[j];
                        return 1;
                    }
                    double mu_y = md->mu * sqrt(1.0 - ratio * ratio);
                    brush(tan_a[j], s * CF[j], s * CM[j], Fz[j], mu_y, &fy, &mz);
                }
                double Fxw = md->tires[j] * fx, Fyw = md->tires[j] * fy;
                if (forces) { forces[b * 2 * na + j] = Fxw; forces[b * 2 * na + na + j] = Fyw; }
                double Mz = md->tires[j] * mz + Mz0[j];
                double Fxb = Fxw * cd[j] - Fyw * sd[j];
                double Fyb = (Fxw * sd[j] + Fyw * cd[j]) + w[1 + j];
                int i = (int)md->au[j];
                F[i][0] += Fxb * e[i][0] + Fyb * n[i][0];
                F[i][1] += Fxb * e[i][1] + Fyb * n[i][1];
                mom[i] += md->x[j] * Fyb + Mz;
            }
            for (int z = 0; z < nz; z++) {
                double acc = 0.0;
                for (int i = 0; i < N; i++) acc += W[i][z][0] * F[i][0] + W[i][z][1] * F[i][1];
                rhs[z] += acc;
            }
            for (int i = 0; i < N; i++) rhs[2 + i] += mom[i];
            double z1[ZMAX];
            memcpy(z1, rhs + 1, sizeof(double) * (N + 1));
            lu_solve(N + 1, Mr, piv, z1);
            double acc = 0.0;
            for (int y = 1; y < nz; y++) acc += M[0][y] * z1[y - 1];
            double D_new = D + (acc - rhs[0]) / dcos_sum;
            int done = decoupled || fabs(D_new - D) <= md->rtol * fmax(1.0, fabs(D_new));
            memcpy(zr, z1, sizeof(double) * (N + 1));
            D = D_new;
            if (done) break;
        }
        dx[0] = V[0][0];
        dx[1] = V[0][1];
        for (int i = 0; i < N; i++) dx[2 + i] = r[i];
        for (int k = 0; k < N + 1; k++) dx[2 + N + k] = zr[k];
        if (Ds) Ds[b] = D;
    }
    return 0;
}

/* The low-speed turn's path-following law compiled (lcvreport/measures/friction_demand.py,
 * PathFollowing): per state, the outside steer wheel's arc length s and signed distance e on the
 * straight-arc-straight path (path_coordinates) and the steer delta = -delta_kin(s) + K e + K_I E.
 * The same arithmetic as the numpy law, one state at a time (tests/test_friction_demand.py holds
 * the two together).  Compiled with -O2 -ffp-contract=off by lcvreport/util/compiled.py.
 */
#include <math.h>

typedef struct {
    double R, a, arc_end, x_m, half_track, K, K_I, U;
    long long G;                /* the delta_kin table: G points */
    const double *grid, *dk;
} Law;

/* np.interp(x, grid, dk): clamped to the ends, linear between */
static double interp(const Law *L, double x)
{
    const double *xp = L->grid, *fp = L->dk;
    long long G = L->G;
    if (isnan(x)) return x;
    if (x < xp[0]) return fp[0];
    if (x >= xp[G - 1]) return fp[G - 1];
    long long lo = 0, hi = G - 1;              /* xp[lo] <= x < xp[hi] */
    while (hi - lo > 1) {
        long long mid = lo + (hi - lo) / 2;
        if (xp[mid] <= x) lo = mid; else hi = mid;
    }
    double slope = (fp[lo + 1] - fp[lo]) / (xp[lo + 1] - xp[lo]);
    return slope * (x - xp[lo]) + fp[lo];
}

/* B states (rows of n: the model's states, the path error's integral E last) at times t (B) */
void lcv_path_following(const Law *L, long long B, const double *t, const double *Xs, int n,
                        double *s_out, double *e_out, double *delta_out)
{
    const double R = L->R, a = L->a, Cx = 0.0, Cy = R;
    const double ex = R * sin(a), ey = R * (1 - cos(a)), tx = cos(a), ty = sin(a);
    const double two_pi = 2 * M_PI;
    for (long long b = 0; b < B; b++) {
        const double *x = Xs + b * n;
        double c = cos(x[2]), sn = sin(x[2]);
        double X = x[0] + L->x_m * c - L->half_track * sn;
        double Y = -(x[1] + L->x_m * sn + L->half_track * c);
        double h = -x[2];       /* unit 1's heading, left positive, unwrapped: the place on the path */
        int approach = h < 0.5 * M_PI, leaving = h > a - 0.5 * M_PI;
        double d[5], s[5], e[5];
        /* the approach, while heading within a quarter turn of its direction */
        d[0] = (X <= 0.0 && approach) ? fabs(Y) : INFINITY;
        s[0] = X; e[0] = Y;
        /* the arc, on the lap nearest the heading */
        double phi = atan2(X - Cx, -(Y - Cy));
        double hc = h < 0.0 ? 0.0 : (h > a ? a : h);
        phi = phi + two_pi * nearbyint((hc - phi) / two_pi);
        double r = hypot(X - Cx, Y - Cy);
        d[1] = (phi >= 0.0 && phi <= a) ? fabs(R - r) : INFINITY;
        s[1] = R * phi; e[1] = R - r;
        /* the exit, while heading within a quarter turn of its direction */
        double along = (X - ex) * tx + (Y - ey) * ty;
        double e2 = tx * (Y - ey) - ty * (X - ex);
        d[2] = (along >= 0.0 && leaving) ? fabs(e2) : INFINITY;
        s[2] = L->arc_end + along; e[2] = e2;
        /* the corners */
        double dc0 = hypot(X, Y), dc1 = hypot(X - ex, Y - ey);
        d[3] = approach ? dc0 : INFINITY; s[3] = 0.0; e[3] = dc0;
        d[4] = leaving ? dc1 : INFINITY; s[4] = L->arc_end; e[4] = dc1;
        int k = 0;
        for (int q = 1; q < 5; q++)
            if (d[q] < d[k] || (isnan(d[q]) && !isnan(d[k]))) k = q;
        s_out[b] = s[k];
        e_out[b] = e[k];
        delta_out[b] = -interp(L, s[k]) + L->K * e[k] + L->K_I * x[n - 1];
    }
}

/*
 * The model of the native FMU: parameters, clamping, input checks, the exact
 * zero-order-hold step, outputs.  The same semantics as lcvreport.fmu.engine (the
 * pythonfmu FMU's engine); the numbers come from vehicle_data.h, generated from the
 * package, so no model equation is written twice.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "linalg.h"
#include "model.h"
#include "vehicle.h"
#include "vehicle_data.h"

static const LcvVehicle *vehicle_of(const ModelInstance *c)
{
    return c->s.vehicle >= 0 ? &LCV_VEHICLES[c->s.vehicle] : NULL;
}

void model_reset(ModelInstance *c)
{
    memset(&c->s, 0, sizeof c->s);
    snprintf(c->s.preset, sizeof c->s.preset, "%s", LCV_DEFAULT_PRESET);
    c->s.tire_scale = LCV_DEFAULT_TIRE_SCALE;
    c->s.u_min = LCV_DEFAULT_U_MIN;
    c->s.crossfall = LCV_DEFAULT_CROSSFALL;
    for (int k = 0; k < LCV_N_INPUTS; ++k) c->s.w[k] = LCV_INPUT_START[k];
    c->s.last_speed = LCV_INPUT_START[0] > LCV_DEFAULT_U_MIN ? LCV_INPUT_START[0] : LCV_DEFAULT_U_MIN;
    c->s.phase = PhaseInstantiated;
    c->s.vehicle = -1;
    c->s.model_exchange = c->model_exchange;
    for (int i = 0; i < LCV_N_STEP_CACHE; ++i) c->steps[i].valid = 0;
    for (int i = 0; i < LCV_N_SPEED_CACHE; ++i) c->speeds[i].valid = 0;
    c->clock = 0;
}

/* ------------------------------------------------------------------ parameters */
static int in_range(double x, double lo, double hi) { return isfinite(x) && x >= lo && x <= hi; }

static int find_vehicle(const char *name)
{
#if LCV_HAS_PRESET
    for (int i = 0; i < LCV_N_VEHICLES; ++i)
        if (strcmp(name, LCV_VEHICLES[i].name) == 0) return i;
    return -1;
#else
    (void)name;
    return 0;
#endif
}

static void build_input_matrix(ModelInstance *c)
{
    const LcvVehicle *v = vehicle_of(c);
    int n = v->n;
    memcpy(c->Bw, v->Bw, sizeof(double) * (size_t)n * LCV_N_INPUTS);
    for (int i = 0; i < n; ++i) {
        c->Bw[i * LCV_N_INPUTS + LCV_IN_DELTA] = c->s.tire_scale * v->Bdelta[i];
        for (int k = 0; k < LCV_N_INPUTS; ++k)          /* a misalignment acts like a steer of its axle */
            if (LCV_INPUT_KIND[k] == LCV_IN_EPS) c->Bw[i * LCV_N_INPUTS + k] *= c->s.tire_scale;
        c->Fc[i] = sin(atan(c->s.crossfall / 100.0)) * v->Bc[i];
    }
}

int model_exit_initialization(ModelInstance *c)
{
    int k = find_vehicle(c->s.preset);
    if (k < 0) {
        snprintf(c->msg, sizeof c->msg, "preset: unknown preset '%s'; valid: %s", c->s.preset, LCV_PRESET_LIST);
        return -1;
    }
    if (!in_range(c->s.tire_scale, LCV_TIRE_SCALE_LOW, LCV_TIRE_SCALE_HIGH)) {
        snprintf(c->msg, sizeof c->msg, "tire_scale must be in [%.4g, %.4g], got %.6g", LCV_TIRE_SCALE_LOW,
                 LCV_TIRE_SCALE_HIGH, c->s.tire_scale);
        return -1;
    }
    if (!in_range(c->s.u_min, LCV_U_MIN_LOW, LCV_U_MIN_HIGH)) {
        snprintf(c->msg, sizeof c->msg, "u_min must be in [%.4g, %.4g] m/s, got %.6g", LCV_U_MIN_LOW,
                 LCV_U_MIN_HIGH, c->s.u_min);
        return -1;
    }
    if (!in_range(c->s.crossfall, LCV_CROSSFALL_LOW, LCV_CROSSFALL_HIGH)) {
        snprintf(c->msg, sizeof c->msg, "crossfall must be in [%.4g, %.4g] %%, got %.6g", LCV_CROSSFALL_LOW,
                 LCV_CROSSFALL_HIGH, c->s.crossfall);
        return -1;
    }
    c->s.vehicle = k;
    for (int i = 0; i < LCV_MAX_M; ++i) c->s.z[i] = 0.0;
    c->s.time = 0.0;
    c->s.clamped = 0;
    c->s.last_speed = c->s.w[0] > c->s.u_min && c->s.w[0] <= LCV_SPEED_MAX ? c->s.w[0] : c->s.u_min;
    for (int i = 0; i < LCV_N_STEP_CACHE; ++i) c->steps[i].valid = 0;
    for (int i = 0; i < LCV_N_SPEED_CACHE; ++i) c->speeds[i].valid = 0;
    build_input_matrix(c);
    return 0;
}

/* ------------------------------------------------------------------ the system at a speed */
static void system_matrices(const LcvVehicle *v, double u, double scale, double *M, double *S)
{
    int nn = v->n * v->n;
    for (int i = 0; i < nn; ++i) {
        M[i] = v->M0[i] + u * v->M1[i];
        S[i] = scale * (v->S0[i] + v->Sinv[i] / u) + v->Skin[i] + u * v->Su[i];
    }
}

/* The speed-dependent output maps (A = M^-1 S, Ca, Da Bw), cached per speed. */
static SpeedEntry *speed_entry(ModelInstance *c, double u)
{
    const LcvVehicle *v = vehicle_of(c);
    SpeedEntry *slot = NULL, *oldest = &c->speeds[0];
    for (int i = 0; i < LCV_N_SPEED_CACHE; ++i) {
        SpeedEntry *e = &c->speeds[i];
        if (e->valid && e->u == u) { e->stamp = ++c->clock; return e; }
        if (!e->valid) { if (!slot) slot = e; }
        else if (e->stamp < oldest->stamp) oldest = e;
    }
    if (!slot) slot = oldest;
    int n = v->n;
    /* work: M (n n) | S, then [S | I] solved in place: n x 2n | solve workspace n n + n */
    double *M = c->work, *SI = M + (size_t)n * n, *ws = SI + 2 * (size_t)n * n;
    double *S = ws;   /* S is assembled in the solve workspace first, then copied */
    system_matrices(v, u, c->s.tire_scale, M, S);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            SI[(size_t)i * 2 * n + j] = S[(size_t)i * n + j];
            SI[(size_t)i * 2 * n + n + j] = i == j ? 1.0 : 0.0;
        }
    slot->valid = 0;
    if (lcv_solve_scaled(M, n, SI, 2 * n, 2 * n, ws) != 0) return NULL;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) slot->A[(size_t)i * n + j] = SI[(size_t)i * 2 * n + j];
    /* XD = FD0 + u FD1; Ca = XD A + X; Da = XD M^-1; DaB = Da Bw + FW0 + s FW1 (ay: XD = V, X = u R) */
    int nf = v->n_fd, ni = LCV_N_INPUTS;
    double scale = c->s.tire_scale;
    double *V = ws, *Da = V + (size_t)nf * n;
    for (int i = 0; i < nf * n; ++i) V[i] = v->FD0[i] + u * v->FD1[i];
    lcv_matmul(V, n, slot->A, n, slot->Ca, n, nf, n, n);
    for (int i = 0; i < nf * n; ++i)
        slot->Ca[i] += v->FX0[i] + u * v->FX1[i] + scale / u * v->FX2[i] + scale * v->FX3[i];
    for (int i = 0; i < nf; ++i)
        for (int j = 0; j < n; ++j) {
            double s = 0.0;
            for (int l = 0; l < n; ++l) s += V[(size_t)i * n + l] * SI[(size_t)l * 2 * n + n + j];
            Da[(size_t)i * n + j] = s;
        }
    lcv_matmul(Da, n, c->Bw, ni, slot->DaB, ni, nf, n, ni);
    for (int i = 0; i < nf * ni; ++i) slot->DaB[i] += v->FW0[i] + scale * v->FW1[i];
    for (int i = 0; i < nf; ++i) {
        double s = 0.0;
        for (int l = 0; l < n; ++l) s += Da[(size_t)i * n + l] * c->Fc[l];
        slot->daF[i] = s;
    }
    slot->u = u;
    slot->eig_state = 0;
    slot->valid = 1;
    slot->stamp = ++c->clock;
    return slot;
}

static int max_real_eig(ModelInstance *c, double u, double *value)
{
    SpeedEntry *e = speed_entry(c, u);
    if (!e) return -1;
    if (e->eig_state == 0) {
        int n = vehicle_of(c)->n;
        double *a = c->work, *wr = a + (size_t)n * n, *wi = wr + n;
        memcpy(a, e->A, sizeof(double) * (size_t)n * n);
        if (lcv_eigenvalues(a, n, wr, wi) != 0) {
            e->eig_state = -1;
        } else {
            double best = wr[0];
            for (int i = 1; i < n; ++i) if (wr[i] > best) best = wr[i];
            e->eig = best;
            e->eig_state = 1;
        }
    }
    if (e->eig_state < 0) return -1;
    *value = e->eig;
    return 0;
}

/* [Ad, Gd Bw] for speed u [m/s] and step h [s], from exp([[A_aug h, G_aug h], [0, 0]]) with
   A_aug = [[M^-1 S, 0], [e_r1, 0, 0], [e_v1, u, 0]], G_aug = [M^-1; 0] (cached). */
static const StepEntry *step_matrix(ModelInstance *c, double u, double h)
{
    const LcvVehicle *v = vehicle_of(c);
    StepEntry *slot = NULL, *oldest = &c->steps[0];
    for (int i = 0; i < LCV_N_STEP_CACHE; ++i) {
        StepEntry *e = &c->steps[i];
        if (e->valid && e->u == u && e->h == h) { e->stamp = ++c->clock; return e; }
        if (!e->valid) { if (!slot) slot = e; }
        else if (e->stamp < oldest->stamp) oldest = e;
    }
    if (!slot) slot = oldest;
    int n = v->n, m = n + 2, nb = m + n, ld = m + LCV_N_INPUTS;
    SpeedEntry *se = speed_entry(c, u);
    if (!se) return NULL;
    /* M^-1 again (the speed entry keeps A only): solve M X = I */
    double *big = c->work, *E = big + (size_t)nb * nb, *Minv = E + (size_t)nb * nb, *ws = Minv + (size_t)n * n;
    double *M = ws + (size_t)n * n + n;
    for (int i = 0; i < n * n; ++i) M[i] = v->M0[i] + u * v->M1[i];
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) Minv[(size_t)i * n + j] = i == j ? 1.0 : 0.0;
    if (lcv_solve_scaled(M, n, Minv, n, n, ws) != 0) return NULL;
    for (size_t i = 0; i < (size_t)nb * nb; ++i) big[i] = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            big[(size_t)i * nb + j] = se->A[(size_t)i * n + j] * h;
            big[(size_t)i * nb + m + j] = Minv[(size_t)i * n + j] * h;
        }
    big[(size_t)n * nb + 1] = h;               /* psi1' = r1 */
    big[(size_t)(n + 1) * nb + 0] = h;         /* Y1' = v1 + u psi1 */
    big[(size_t)(n + 1) * nb + n] = u * h;
    slot->valid = 0;
    if (lcv_expm(big, nb, E, Minv) != 0) return NULL;   /* Minv's storage reused as expm workspace */
    for (int i = 0; i < m; ++i) {
        for (int j = 0; j < m; ++j) slot->K[(size_t)i * ld + j] = E[(size_t)i * nb + j];
        for (int j = 0; j < LCV_N_INPUTS; ++j) {
            double s = 0.0;
            for (int l = 0; l < n; ++l) s += E[(size_t)i * nb + m + l] * c->Bw[(size_t)l * LCV_N_INPUTS + j];
            slot->K[(size_t)i * ld + m + j] = s;
        }
        double g = 0.0;
        for (int l = 0; l < n; ++l) g += E[(size_t)i * nb + m + l] * c->Fc[l];
        slot->gc[i] = g;
    }
    slot->valid = 1;
    slot->u = u;
    slot->h = h;
    slot->stamp = ++c->clock;
    return slot;
}

/* ------------------------------------------------------------------ inputs and steps */
/* the first input that is not finite or out of range (with the speed: above its maximum)
   into c->msg; -1 if there is one */
static int check_inputs_(ModelInstance *c, int speed)
{
    for (int k = 0; k < LCV_N_INPUTS; ++k) {
        double x = c->s.w[k];
        const char *name = LCV_VARIABLE_NAMES[LCV_FIRST_INPUT + k];
        if (!isfinite(x)) {
            snprintf(c->msg, sizeof c->msg, "input %s is not finite (%g); the step is refused and the state is "
                     "unchanged", name, x);
            return -1;
        }
        double lim = 0.0;
        switch (LCV_INPUT_KIND[k]) {
        case LCV_IN_SPEED:
            if (speed && x > LCV_SPEED_MAX) {
                snprintf(c->msg, sizeof c->msg, "input u = %.6g m/s is above %.4g m/s, the fastest speed the model "
                         "is run at; the step is refused and the state is unchanged", x, LCV_SPEED_MAX);
                return -1;
            }
            continue;
        case LCV_IN_STEER: lim = LCV_STEER_MAX; break;
        case LCV_IN_FORCE: lim = LCV_FORCE_MAX; break;
        case LCV_IN_EPS: lim = LCV_EPS_MAX; break;
        default: lim = LCV_MOMENT_MAX; break;
        }
        if (fabs(x) > lim) {
            snprintf(c->msg, sizeof c->msg, "input %s = %.6g is outside [%.4g, %.4g]; the step is refused and the "
                     "state is unchanged", name, x, -lim, lim);
            return -1;
        }
    }
    return 0;
}

static int check_inputs(ModelInstance *c) { return check_inputs_(c, 1); }

/* the speed the model runs at (u clamped to u_min); *warn = 1 with the message in c->msg the
   first time u falls below u_min */
static double clamped_speed(ModelInstance *c, int *clamped, int *warn)
{
    double u_in = c->s.w[0];
    *clamped = u_in < c->s.u_min;
    *warn = 0;
    if (*clamped && !c->s.clamped) {
        snprintf(c->msg, sizeof c->msg, "u = %.6g m/s is below u_min = %.6g m/s; the model runs at u_min until u "
                 "rises again (the linear model needs a forward speed)", u_in, c->s.u_min);
        *warn = 1;
    }
    return *clamped ? c->s.u_min : u_in;
}

int model_do_step(ModelInstance *c, double h)
{
    if (!(isfinite(h) && h >= LCV_STEP_LOW && h <= LCV_STEP_HIGH)) {
        snprintf(c->msg, sizeof c->msg, "communication step size must be in [%.4g, %.4g] s, got %.17g; the step "
                 "is refused", LCV_STEP_LOW, LCV_STEP_HIGH, h);
        return -1;
    }
    if (check_inputs(c) != 0) return -1;
    const LcvVehicle *v = vehicle_of(c);
    int m = v->n + 2, ld = m + LCV_N_INPUTS;
    int clamped, warn;
    double u = clamped_speed(c, &clamped, &warn);
    const StepEntry *step = step_matrix(c, u, h);
    const double *K = step ? step->K : NULL;
    if (!K) {
        snprintf(c->msg, sizeof c->msg, "the discretization failed at u = %.6g m/s, h = %.6g s (not finite); the "
                 "step is refused and the state is unchanged", u, h);
        return -1;
    }
    double znew[LCV_MAX_M], x[LCV_MAX_M + LCV_N_INPUTS];
    memcpy(x, c->s.z, sizeof(double) * (size_t)m);              /* [z, w]: one contiguous dot per row */
    memcpy(x + m, c->s.w, sizeof(double) * LCV_N_INPUTS);
    for (int i = 0; i < m; ++i) {
        const double *row = K + (size_t)i * ld;
        /* four independent accumulators: the additions of a row overlap instead of waiting on
           each other (one serial chain was latency-bound); a fixed order, so results are
           reproducible and differ from the serial sum by rounding only */
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
        int j = 0;
        for (; j + 4 <= ld; j += 4) {
            s0 += row[j] * x[j];
            s1 += row[j + 1] * x[j + 1];
            s2 += row[j + 2] * x[j + 2];
            s3 += row[j + 3] * x[j + 3];
        }
        for (; j < ld; ++j) s0 += row[j] * x[j];
        double s = ((s0 + s1) + (s2 + s3)) + step->gc[i];
        if (!isfinite(s)) {
            double e = 0.0;
            int ok = max_real_eig(c, u, &e) == 0;
            snprintf(c->msg, sizeof c->msg, "the step to t = %.6g s is refused: its result is not finite (the vehicle "
                     "is unstable at u = %.6g m/s, max Re(lambda) = %s%.4g 1/s); the state is unchanged",
                     c->s.time + h, u, ok ? "" : "unknown ", ok ? e : 0.0);
            return -1;
        }
        znew[i] = s;
    }
    memcpy(c->s.z, znew, sizeof(double) * (size_t)m);
    c->s.time += h;
    c->s.clamped = clamped;
    c->s.last_speed = u;
    return warn;
}

/* ------------------------------------------------------------------ Model Exchange */
const char *model_variable_name(unsigned vr)
{
    return vr < LCV_N_VARIABLES ? LCV_VARIABLE_NAMES[vr] : "?";
}

unsigned model_me_state_vr(size_t k) { return k < LCV_N_ME_STATES ? LCV_ME_STATE_VR[k] : 0u; }

void model_get_nominals(ModelInstance *c, double x[], size_t nx)
{
    (void)c;
    for (size_t i = 0; i < nx && i < LCV_N_ME_STATES; ++i) x[i] = LCV_ME_NOMINAL[i];
}

void model_get_states(ModelInstance *c, double x[], size_t nx)
{
    const LcvVehicle *v = vehicle_of(c);
    for (size_t k = 0; k < nx && k < LCV_N_ME_STATES; ++k) {
        int j = v ? v->me_z[k] : -1;
        x[k] = j >= 0 ? c->s.z[j] : 0.0;
    }
}

void model_set_states(ModelInstance *c, const double x[], size_t nx)
{
    const LcvVehicle *v = vehicle_of(c);
    if (!v) return;
    for (size_t k = 0; k < nx && k < LCV_N_ME_STATES; ++k) {
        int j = v->me_z[k];
        if (j >= 0) c->s.z[j] = x[k];
    }
}

/* z' = [M^-1 (S x + Bw w + Fc); r1; v1 + u psi1] at the current inputs (u clamped to u_min):
   0, 1 with a warning in c->msg (u clamped), -1 with an error in c->msg */
int model_derivatives(ModelInstance *c, double dx[], size_t nx)
{
    const LcvVehicle *v = vehicle_of(c);
    for (size_t k = 0; k < nx; ++k) dx[k] = 0.0;
    if (!v) return 0;                                  /* before initialization: at rest */
    if (check_inputs(c) != 0) return -1;
    int n = v->n;
    int clamped, warn;
    double u = clamped_speed(c, &clamped, &warn);
    c->s.clamped = clamped;
    SpeedEntry *se = speed_entry(c, u);
    if (!se) {
        snprintf(c->msg, sizeof c->msg, "the state matrix cannot be evaluated at u = %.6g m/s", u);
        return -1;
    }
    double *M = c->work, *y = M + (size_t)n * n, *ws = y + n;
    for (int i = 0; i < n * n; ++i) M[i] = v->M0[i] + u * v->M1[i];
    for (int i = 0; i < n; ++i) {
        double s = c->Fc[i];
        for (int j = 0; j < LCV_N_INPUTS; ++j) s += c->Bw[(size_t)i * LCV_N_INPUTS + j] * c->s.w[j];
        y[i] = s;
    }
    if (lcv_solve_scaled(M, n, y, 1, 1, ws) != 0) {
        snprintf(c->msg, sizeof c->msg, "the mass matrix is singular at u = %.6g m/s", u);
        return -1;
    }
    double dz[LCV_MAX_M];
    for (int i = 0; i < n; ++i) {
        double s = y[i];
        for (int j = 0; j < n; ++j) s += se->A[(size_t)i * n + j] * c->s.z[j];
        dz[i] = s;
    }
    dz[n] = c->s.z[1];                                  /* psi1' = r1 */
    dz[n + 1] = c->s.z[0] + u * c->s.z[n];              /* Y1' = v1 + u psi1 */
    for (int i = 0; i < n + 2; ++i)
        if (!isfinite(dz[i])) {
            snprintf(c->msg, sizeof c->msg, "the derivatives at t = %.6g s are not finite", c->s.time);
            return -1;
        }
    for (size_t k = 0; k < nx && k < LCV_N_ME_STATES; ++k) {
        int j = v->me_z[k];
        dx[k] = j >= 0 ? dz[j] : 0.0;
    }
    c->s.last_speed = u;
    return warn;
}

/* Directional derivatives (the model is linear in z and in every input but u, for fixed u):
   knowns are Model Exchange states and inputs other than u; unknowns are derivatives der(x)
   and outputs other than max_real_eig.  0, or -1 with c->msg. */
int model_directional(ModelInstance *c, const unsigned unknowns[], size_t nu, const unsigned knowns[], size_t nk,
                      const double seed[], double out[])
{
    const LcvVehicle *v = vehicle_of(c);
    for (size_t i = 0; i < nu; ++i) out[i] = 0.0;
    /* every value reference is checked first, in every phase the call is allowed in */
    for (size_t i = 0; i < nk; ++i) {
        unsigned r = knowns[i];
        int ok = r >= LCV_FIRST_INPUT + 1 && r < LCV_FIRST_INPUT + LCV_N_INPUTS;
        for (int j = 0; j < LCV_N_ME_STATES && !ok; ++j) ok = LCV_ME_STATE_VR[j] == r;
        if (!ok) {
            snprintf(c->msg, sizeof c->msg, "directional derivative: known %u (%s) is not a continuous state or an "
                     "input other than u (the model is nonlinear in u)", r, model_variable_name(r));
            return -1;
        }
    }
    for (size_t i = 0; i < nu; ++i) {
        unsigned r = unknowns[i];
        if (r >= LCV_FIRST_DERIVATIVE && r < LCV_FIRST_DERIVATIVE + LCV_N_ME_STATES) continue;
        if (!(r >= LCV_FIRST_OUTPUT && r < LCV_FIRST_OUTPUT + LCV_N_OUTPUTS)) {
            snprintf(c->msg, sizeof c->msg, "directional derivative: unknown %u (%s) is not an output or a derivative",
                     r, model_variable_name(r));
            return -1;
        }
        int kind = LCV_OUTPUT_KIND[r - LCV_FIRST_OUTPUT];
        if (kind != LCV_OUT_LINEAR && kind != LCV_OUT_LATERAL && kind != LCV_OUT_ACCEL) {
            snprintf(c->msg, sizeof c->msg, "directional derivative: %s is not differentiable (the largest real part "
                     "of the eigenvalues)", model_variable_name(r));
            return -1;
        }
    }
    if (!v) return 0;                                  /* before initialization: at rest, nothing depends */
    int n = v->n, m = n + 2, N = v->n_units;
    double dz[LCV_MAX_M] = {0}, dw[LCV_N_INPUTS] = {0};
    for (size_t i = 0; i < nk; ++i) {
        unsigned r = knowns[i];
        if (r >= LCV_FIRST_INPUT + 1 && r < LCV_FIRST_INPUT + LCV_N_INPUTS) { dw[r - LCV_FIRST_INPUT] += seed[i]; continue; }
        int k = -1;
        for (int j = 0; j < LCV_N_ME_STATES; ++j) if (LCV_ME_STATE_VR[j] == r) { k = j; break; }
        if (k < 0) {
            snprintf(c->msg, sizeof c->msg, "directional derivative: known %u (%s) is not a continuous state or an "
                     "input other than u (the model is nonlinear in u)", r, model_variable_name(r));
            return -1;
        }
        if (v->me_z[k] >= 0) dz[v->me_z[k]] += seed[i];
    }
    double u_in = c->s.w[0], u = u_in < c->s.u_min ? c->s.u_min : u_in;
    if (!(u <= LCV_SPEED_MAX)) { snprintf(c->msg, sizeof c->msg, "input u = %.6g m/s is above %.4g m/s", u_in, LCV_SPEED_MAX); return -1; }
    SpeedEntry *se = speed_entry(c, u);
    if (!se) { snprintf(c->msg, sizeof c->msg, "the state matrix cannot be evaluated at u = %.6g m/s", u); return -1; }
    double ddz[LCV_MAX_M];
    int need_dynamics = 0;
    for (size_t i = 0; i < nu; ++i)
        if (unknowns[i] >= LCV_FIRST_DERIVATIVE && unknowns[i] < LCV_FIRST_DERIVATIVE + LCV_N_ME_STATES) need_dynamics = 1;
    if (need_dynamics) {                                /* d(z') = A_aug dz + G Bw dw */
        double *M = c->work, *y = M + (size_t)n * n, *ws = y + n;
        for (int i = 0; i < n * n; ++i) M[i] = v->M0[i] + u * v->M1[i];
        for (int i = 0; i < n; ++i) {
            double s = 0.0;
            for (int j = 0; j < LCV_N_INPUTS; ++j) s += c->Bw[(size_t)i * LCV_N_INPUTS + j] * dw[j];
            y[i] = s;
        }
        if (lcv_solve_scaled(M, n, y, 1, 1, ws) != 0) {
            snprintf(c->msg, sizeof c->msg, "the mass matrix is singular at u = %.6g m/s", u);
            return -1;
        }
        for (int i = 0; i < n; ++i) {
            double s = y[i];
            for (int j = 0; j < n; ++j) s += se->A[(size_t)i * n + j] * dz[j];
            ddz[i] = s;
        }
        ddz[n] = dz[1];
        ddz[n + 1] = dz[0] + u * dz[n];
    }
    for (size_t i = 0; i < nu; ++i) {
        unsigned r = unknowns[i];
        if (r >= LCV_FIRST_DERIVATIVE && r < LCV_FIRST_DERIVATIVE + LCV_N_ME_STATES) {
            int j = v->me_z[r - LCV_FIRST_DERIVATIVE];
            out[i] = j >= 0 ? ddz[j] : 0.0;
            continue;
        }
        if (!(r >= LCV_FIRST_OUTPUT && r < LCV_FIRST_OUTPUT + LCV_N_OUTPUTS)) {
            snprintf(c->msg, sizeof c->msg, "directional derivative: unknown %u (%s) is not an output or a derivative",
                     r, model_variable_name(r));
            return -1;
        }
        int o = (int)(r - LCV_FIRST_OUTPUT);
        double s = 0.0;
        switch (LCV_OUTPUT_KIND[o]) {
        case LCV_OUT_LINEAR:
            for (int j = 0; j < m; ++j) s += v->C[(size_t)o * m + j] * dz[j];
            break;
        case LCV_OUT_LATERAL:                           /* y = C z + W sin(H z): dy = C dz + W cos(H z) H dz */
            for (int j = 0; j < m; ++j) s += v->C[(size_t)o * m + j] * dz[j];
            for (int k = 0; k < N - 1; ++k) {
                double hz = 0.0, hd = 0.0;
                for (int j = 0; j < m; ++j) { hz += v->H[(size_t)k * m + j] * c->s.z[j]; hd += v->H[(size_t)k * m + j] * dz[j]; }
                s += v->W[(size_t)o * (N - 1) + k] * cos(hz) * hd;
            }
            break;
        case LCV_OUT_ACCEL: {
            int iu = v->fd_row[o];
            if (iu < 0) break;
            for (int j = 0; j < n; ++j) s += se->Ca[(size_t)iu * n + j] * dz[j];
            for (int j = 0; j < LCV_N_INPUTS; ++j) s += se->DaB[(size_t)iu * LCV_N_INPUTS + j] * dw[j];
            break;
        }
        default:
            snprintf(c->msg, sizeof c->msg, "directional derivative: %s is not differentiable (the largest real part "
                     "of the eigenvalues)", model_variable_name(r));
            return -1;
        }
        out[i] = s;
    }
    return 0;
}

/* ------------------------------------------------------------------ outputs */
static double output_speed(const ModelInstance *c)
{
    double u = c->s.w[0];
    if (isfinite(u) && u <= LCV_SPEED_MAX) return u < c->s.u_min ? c->s.u_min : u;
    return c->s.last_speed;
}

/* the outputs o with want[o] into out[]; valid[o] = 0 where one cannot be evaluated (c->msg says
   why); only what a host asks for is computed (a host reading one output pays for one) */
static void compute_outputs(ModelInstance *c, const char *want, double *out, int *valid)
{
    const LcvVehicle *v = vehicle_of(c);
    int n = v->n, m = n + 2, N = v->n_units;
    char why[1024] = "";
    int inputs_ok = -1, have_sin = 0;
    double theta_sin[LCV_MAX_UNITS] = {0};        /* a single unit has none (and gcc must see it set) */
    double u = output_speed(c);
    SpeedEntry *se = NULL;
    for (int o = 0; o < LCV_N_OUTPUTS; ++o) {
        double s = 0.0;
        valid[o] = 1;
        if (!want[o]) { out[o] = 0.0; continue; }
        if (LCV_OUTPUT_KIND[o] == LCV_OUT_LATERAL && !have_sin) {
            for (int k = 0; k < N - 1; ++k) {
                double hz = 0.0;
                for (int j = 0; j < m; ++j) hz += v->H[(size_t)k * m + j] * c->s.z[j];
                theta_sin[k] = sin(hz);
            }
            have_sin = 1;
        }
        switch (LCV_OUTPUT_KIND[o]) {
        case LCV_OUT_LINEAR:
            for (int j = 0; j < m; ++j) s += v->C[(size_t)o * m + j] * c->s.z[j];
            break;
        case LCV_OUT_LATERAL:                           /* y = C z + W sin(H z) (C: the yaw-roll model's roll offsets) */
            for (int j = 0; j < m; ++j) s += v->C[(size_t)o * m + j] * c->s.z[j];
            for (int k = 0; k < N - 1; ++k) s += v->W[(size_t)o * (N - 1) + k] * theta_sin[k];
            break;
        case LCV_OUT_ACCEL: {
            int i = v->fd_row[o];
            if (i < 0) break;
            if (inputs_ok < 0) {
                inputs_ok = check_inputs_(c, 0) == 0;
                if (!inputs_ok) snprintf(why, sizeof why, "the lateral accelerations depend on the inputs: %.900s", c->msg);
            }
            if (!inputs_ok) { valid[o] = 0; break; }
            if (!se && !(se = speed_entry(c, u))) {
                snprintf(why, sizeof why, "the lateral accelerations cannot be evaluated at u = %.6g m/s", u);
                valid[o] = 0;
                break;
            }
            for (int j = 0; j < n; ++j) s += se->Ca[(size_t)i * n + j] * c->s.z[j];
            for (int j = 0; j < LCV_N_INPUTS; ++j) s += se->DaB[(size_t)i * LCV_N_INPUTS + j] * c->s.w[j];
            s += se->daF[i];
            break;
        }
        default:
            if (max_real_eig(c, u, &s) != 0) {
                snprintf(why, sizeof why, "the eigenvalues at u = %.6g m/s did not converge", u);
                valid[o] = 0;
            }
            break;
        }
        if (valid[o] && !isfinite(s)) {
            snprintf(why, sizeof why, "output %s is not finite", LCV_VARIABLE_NAMES[LCV_FIRST_OUTPUT + o]);
            valid[o] = 0;
        }
        out[o] = valid[o] ? s : 0.0;
    }
    if (why[0]) snprintf(c->msg, sizeof c->msg, "%s", why);
}

int model_get_real(ModelInstance *c, const unsigned vr[], size_t nvr, double value[])
{
    double out[LCV_N_OUTPUTS];
    int valid[LCV_N_OUTPUTS];
    char want[LCV_N_OUTPUTS];
    int have = 0, status = 0;
    memset(want, 0, sizeof want);
    for (size_t i = 0; i < nvr; ++i)
        if (vr[i] >= LCV_FIRST_OUTPUT && vr[i] < LCV_FIRST_OUTPUT + LCV_N_OUTPUTS) want[vr[i] - LCV_FIRST_OUTPUT] = 1;
    for (size_t i = 0; i < nvr; ++i) {
        unsigned r = vr[i];
        switch (r) {
        case vr_tire_scale: value[i] = c->s.tire_scale; continue;
        case vr_u_min: value[i] = c->s.u_min; continue;
        case vr_crossfall: value[i] = c->s.crossfall; continue;
        default: break;
        }
        if (r >= LCV_FIRST_INPUT && r < LCV_FIRST_INPUT + LCV_N_INPUTS) {
            value[i] = c->s.w[r - LCV_FIRST_INPUT];
        } else if (r >= LCV_FIRST_DERIVATIVE && r < LCV_FIRST_DERIVATIVE + LCV_N_ME_STATES) {
            double dx[LCV_N_ME_STATES];
            int clamped = c->s.clamped;             /* a read does not consume the clamping warning */
            int d = model_derivatives(c, dx, LCV_N_ME_STATES);
            c->s.clamped = clamped;
            value[i] = d < 0 ? 0.0 : dx[r - LCV_FIRST_DERIVATIVE];
            if (d < 0) status = -1;
        } else if (r >= LCV_FIRST_OUTPUT && r < LCV_FIRST_OUTPUT + LCV_N_OUTPUTS) {
            value[i] = 0.0;
            if (c->s.vehicle < 0) continue;                /* before initialization: at rest */
            if (!have) {
                compute_outputs(c, want, out, valid);
                have = 1;
            }
            value[i] = out[r - LCV_FIRST_OUTPUT];
            if (!valid[r - LCV_FIRST_OUTPUT]) status = -1;
        } else {
            value[i] = 0.0;
            snprintf(c->msg, sizeof c->msg, "%u is not the value reference of a Real variable", r);
            status = -1;
        }
    }
    return status;
}

int model_set_real(ModelInstance *c, unsigned vr, double value)
{
    switch (vr) {
    case vr_tire_scale:
    case vr_u_min:
    case vr_crossfall:
        if (!(c->s.phase & (PhaseInstantiated | PhaseInitializationMode))) {
            snprintf(c->msg, sizeof c->msg, "%s is a fixed parameter: it cannot change after initialization",
                     LCV_VARIABLE_NAMES[vr]);
            return -1;
        }
        if (vr == vr_tire_scale) c->s.tire_scale = value;
        else if (vr == vr_u_min) c->s.u_min = value;
        else c->s.crossfall = value;
        return 0;
    default:
        break;
    }
    if (vr >= LCV_FIRST_INPUT && vr < LCV_FIRST_INPUT + LCV_N_INPUTS) {
        c->s.w[vr - LCV_FIRST_INPUT] = value;
        return 0;
    }
    snprintf(c->msg, sizeof c->msg, "%u is not the value reference of an input or a Real parameter",
             (unsigned)vr);
    return -1;
}

int model_get_string(ModelInstance *c, unsigned vr, const char **value)
{
#if LCV_HAS_PRESET
    if (vr == vr_preset) { *value = c->s.preset; return 0; }
#endif
    *value = "";
    snprintf(c->msg, sizeof c->msg, "%u is not the value reference of a String variable", (unsigned)vr);
    return -1;
}

int model_set_string(ModelInstance *c, unsigned vr, const char *value)
{
#if LCV_HAS_PRESET
    if (vr == vr_preset) {
        if (!(c->s.phase & (PhaseInstantiated | PhaseInitializationMode))) {
            snprintf(c->msg, sizeof c->msg, "preset is a fixed parameter: it cannot change after initialization");
            return -1;
        }
        const char *text = value ? value : "";
        /* a name longer than the buffer is kept truncated: it is no preset, initialization names it */
        snprintf(c->s.preset, sizeof c->s.preset, "%s", text);
        return 0;
    }
#endif
    (void)value;
    snprintf(c->msg, sizeof c->msg, "%u is not the value reference of a String variable", (unsigned)vr);
    return -1;
}

/* preset, the Enumeration (SPEC section 15): value k is the k-th preset, 1-based */
int model_get_integer(ModelInstance *c, unsigned vr, int *value)
{
#if LCV_HAS_PRESET
    if (vr == vr_preset) {
        int k = find_vehicle(c->s.preset);
        *value = k < 0 ? 0 : k + 1;   /* 0: a name set through SetString that is no preset */
        return 0;
    }
#endif
    *value = 0;
    snprintf(c->msg, sizeof c->msg, "%u is not the value reference of an Enumeration variable", (unsigned)vr);
    return -1;
}

int model_set_integer(ModelInstance *c, unsigned vr, long long value)
{
#if LCV_HAS_PRESET
    if (vr == vr_preset) {
        if (value < 1 || value > LCV_N_VEHICLES) {
            snprintf(c->msg, sizeof c->msg, "preset: %lld is not a preset; valid: 1 to %d (%s)", value,
                     LCV_N_VEHICLES, LCV_PRESET_LIST);
            return -1;
        }
        if (!(c->s.phase & (PhaseInstantiated | PhaseInitializationMode))) {
            snprintf(c->msg, sizeof c->msg, "preset is a fixed parameter: it cannot change after initialization");
            return -1;
        }
        snprintf(c->s.preset, sizeof c->s.preset, "%s", LCV_VEHICLES[value - 1].name);
        return 0;
    }
#endif
    (void)value;
    snprintf(c->msg, sizeof c->msg, "%u is not the value reference of an Enumeration variable", (unsigned)vr);
    return -1;
}

/* ------------------------------------------------------------------ FMU state */
int model_check_state(ModelInstance *c, const ModelState *s)
{
    if (memchr(s->preset, '\0', sizeof s->preset) == NULL || memchr(s->error, '\0', sizeof s->error) == NULL) {
        snprintf(c->msg, sizeof c->msg, "the FMU state is refused: its text fields are not terminated");
        return -1;
    }
    if (s->model_exchange != c->model_exchange) {
        snprintf(c->msg, sizeof c->msg, "the FMU state is refused: it was written by a %s instance, this one is a %s",
                 s->model_exchange ? "Model Exchange" : "Co-Simulation",
                 c->model_exchange ? "Model Exchange" : "Co-Simulation");
        return -1;
    }
    int phases = PhaseInstantiated | PhaseInitializationMode | PhaseTerminated | PhaseError |
                 (c->model_exchange ? PhaseEventMode | PhaseContinuousTimeMode : PhaseStepComplete);
    /* one phase of this interface; a vehicle exactly when initialization has built one (StepComplete,
       EventMode, ContinuousTimeMode and Terminated need it, Instantiated and InitializationMode have none) */
    int needs_vehicle = s->phase == PhaseStepComplete || s->phase == PhaseTerminated || s->phase == PhaseEventMode ||
                        s->phase == PhaseContinuousTimeMode;
    int has_none = s->phase == PhaseInstantiated || s->phase == PhaseInitializationMode;
    if (!(s->phase & phases) || (s->phase & (s->phase - 1)) || s->vehicle < -1 || s->vehicle >= LCV_N_VEHICLES ||
        (needs_vehicle && s->vehicle < 0) || (has_none && s->vehicle >= 0)) {
        snprintf(c->msg, sizeof c->msg, "the FMU state is refused: it was not written by this FMU");
        return -1;
    }
    int finite = isfinite(s->tire_scale) && isfinite(s->u_min) && isfinite(s->time) && isfinite(s->last_speed) &&
                 isfinite(s->crossfall);
    for (int i = 0; i < LCV_MAX_M; ++i) finite = finite && isfinite(s->z[i]);
    for (int k = 0; k < LCV_N_INPUTS; ++k) finite = finite && !isnan(s->w[k]);
    if (!finite) {
        snprintf(c->msg, sizeof c->msg, "the FMU state is refused: it holds numbers that are not finite");
        return -1;
    }
    if (s->vehicle >= 0 && (!in_range(s->tire_scale, LCV_TIRE_SCALE_LOW, LCV_TIRE_SCALE_HIGH) ||
                            !in_range(s->u_min, LCV_U_MIN_LOW, LCV_U_MIN_HIGH) ||
                            !in_range(s->crossfall, LCV_CROSSFALL_LOW, LCV_CROSSFALL_HIGH))) {
        snprintf(c->msg, sizeof c->msg, "the FMU state is refused: its parameters are out of range");
        return -1;
    }
    return 0;
}

void model_state_restored(ModelInstance *c, const ModelState *before)
{
    if (!(c->s.vehicle == before->vehicle && c->s.tire_scale == before->tire_scale &&
          c->s.crossfall == before->crossfall)) {
        for (int i = 0; i < LCV_N_STEP_CACHE; ++i) c->steps[i].valid = 0;
        for (int i = 0; i < LCV_N_SPEED_CACHE; ++i) c->speeds[i].valid = 0;
    }
    if (c->s.vehicle >= 0) build_input_matrix(c);
}

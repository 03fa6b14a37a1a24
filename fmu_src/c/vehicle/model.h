/*
 * The vehicle model behind the native FMUs: what the FMI API files (api/fmi2_api.c,
 * api/fmi3_api.c) call, FMI-neutral (no FMI type: the API files hold what is FMI's -- the
 * host's callbacks, the status codes -- and name the FMI function in their messages).  The
 * model (parameters, clamping, checks, exact steps, outputs) is in model.c, the linear
 * algebra in linalg.c.  config.h (the interface table: the ValueReference enum, sizes,
 * ranges) and vehicle_data.h (the matrices of the vehicle or the six presets) are generated
 * by lcvreport.fmu.build.
 */
#ifndef LCV_MODEL_H
#define LCV_MODEL_H

#include <stddef.h>

#include "fmu_common.h"
#include "config.h"

/* Everything that evolves: copied by GetFMUState and serialized as bytes. */
typedef struct {
    char preset[64];                    /* preset name (preset FMU) */
    double tire_scale, u_min;           /* fixed parameters */
    double w[LCV_N_INPUTS];             /* inputs, SI, interface order (u first) */
    double z[LCV_MAX_M];                /* [x, psi1, Y1], SI */
    double time, last_speed;            /* [s], speed of the last step [m/s] */
    int clamped;                        /* u below u_min at the last step */
    int phase;                          /* Phase */
    int vehicle;                        /* index into LCV_VEHICLES, -1 before initialization */
    char error[1024];                   /* why the instance is in PhaseError */
    double crossfall;                   /* fixed parameter [%] */
    int model_exchange;                 /* written by a Model Exchange instance (1) or a Co-Simulation one (0) */
} ModelState;

typedef struct {
    int valid;
    double u, h;
    unsigned long stamp;
    double K[LCV_MAX_M * (LCV_MAX_M + LCV_N_INPUTS)];   /* [Ad, Gd Bw] row-major, ld = m + NW */
    double gc[LCV_MAX_M];                               /* Gd Fc: the crossfall's share of a step */
} StepEntry;

typedef struct {
    int valid;
    double u;
    unsigned long stamp;
    double A[LCV_MAX_STATES * LCV_MAX_STATES];          /* M^-1 S */
    double Ca[LCV_MAX_FD * LCV_MAX_STATES];             /* feedthrough rows (ay, extras): Ca x + DaB w + daF */
    double DaB[LCV_MAX_FD * LCV_N_INPUTS];
    double daF[LCV_MAX_FD];                             /* the crossfall's part */
    int eig_state;                                      /* 0 not computed, 1 ok, -1 failed */
    double eig;                                         /* max real part [1/s] */
} SpeedEntry;

#define LCV_N_STEP_CACHE 16
#define LCV_N_SPEED_CACHE 16

typedef struct ModelInstance {
    char *name;
    int logging_on;
    int model_exchange;                                  /* instantiated for Model Exchange */
    ModelState s;
    double Bw[LCV_MAX_STATES * LCV_N_INPUTS];            /* generalized force per SI input, tire-scaled */
    double Fc[LCV_MAX_STATES];                           /* the crossfall's constant generalized force */
    StepEntry steps[LCV_N_STEP_CACHE];
    SpeedEntry speeds[LCV_N_SPEED_CACHE];
    unsigned long clock;
    double work[LCV_WORK];                               /* workspace of the linear algebra */
    char msg[1024];                                      /* message of the last warning or error */
} ModelInstance;

/* names of variables and of the Model Exchange states (for messages) */
const char *model_variable_name(unsigned vr);
#define LCV_VARIABLE_NAME(vr) model_variable_name(vr)
unsigned model_me_state_vr(size_t k);
#define LCV_ME_STATE_VR_OF(k) model_me_state_vr(k)

/* the model API (api/model_api.h); here: the Model Exchange states are the interface's (v1, r..,
   theta.., psi1, Y1; 0 for what the vehicle lacks), their nominals the peaks of the standard single
   sine; directional derivatives are with respect to states and inputs other than u; a restored FMU
   state drops the caches if the vehicle, the tire scale or the crossfall changed */
#include "model_api.h"

#endif

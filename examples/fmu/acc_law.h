/* The time-gap ACC law of examples/acc_controller.py (TimeGapACC), in C, operation for
 * operation in the same order, so that the FMU and the Python controller command the same
 * doubles (compile with -ffp-contract=off: no fused multiply-add).
 *
 * Units: m, s, m/s, m/s^2. Value references are shared by the FMI 2 and FMI 3 wrappers. */
#ifndef ACC_LAW_H
#define ACC_LAW_H

/* inputs */
#define VR_V_EGO 0         /* own speed [m/s] */
#define VR_GAP 1           /* bumper-to-bumper gap to the leader [m], +inf without one */
#define VR_V_REL 2         /* leader speed minus own speed [m/s] */
#define VR_HAS_LEAD 3      /* Boolean: a leader is seen */
/* outputs */
#define VR_A_CMD 4         /* commanded acceleration [m/s^2] */
#define VR_V_CMD 5         /* commanded speed after the step, v + a*dt [m/s] */
/* parameters */
#define VR_TIME_GAP 10     /* T [s] */
#define VR_STANDSTILL 11   /* s0 [m] */
#define VR_GAP_GAIN 12     /* k_gap [1/s^2] */
#define VR_REL_GAIN 13     /* k_rel [1/s] */
#define VR_SET_SPEED 14    /* v_set [m/s] */
#define VR_CRUISE_GAIN 15  /* k_cruise [1/s] */
#define VR_MAX_ACCEL 16    /* [m/s^2] */
#define VR_MAX_DECEL 17    /* [m/s^2], positive */
#define N_REALS 18

typedef struct {
    double r[N_REALS]; /* every Real by value reference (inputs, outputs, parameters) */
    int has_lead;
} AccState;

static void acc_defaults(AccState *s) {
    int i;
    for (i = 0; i < N_REALS; i++) s->r[i] = 0.0;
    s->has_lead = 0;
    s->r[VR_TIME_GAP] = 1.5;
    s->r[VR_STANDSTILL] = 5.0;
    s->r[VR_GAP_GAIN] = 0.3;
    s->r[VR_REL_GAIN] = 0.8;
    s->r[VR_SET_SPEED] = 30.0;
    s->r[VR_CRUISE_GAIN] = 0.4;
    s->r[VR_MAX_ACCEL] = 3.0;
    s->r[VR_MAX_DECEL] = 6.0;
}

/* One evaluation: the outputs from the inputs held over the step of length dt [s]. */
static void acc_step(AccState *s, double dt) {
    const double *r = s->r;
    double v = r[VR_V_EGO];
    double accel = r[VR_CRUISE_GAIN] * (r[VR_SET_SPEED] - v);
    if (s->has_lead) {
        double spacing_error = r[VR_GAP] - (r[VR_STANDSTILL] + r[VR_TIME_GAP] * v);
        double a_gap = r[VR_GAP_GAIN] * spacing_error + r[VR_REL_GAIN] * r[VR_V_REL];
        if (a_gap < accel) accel = a_gap;
    }
    if (accel < -r[VR_MAX_DECEL]) accel = -r[VR_MAX_DECEL];
    if (accel > r[VR_MAX_ACCEL]) accel = r[VR_MAX_ACCEL];
    s->r[VR_A_CMD] = accel;
    s->r[VR_V_CMD] = v + accel * dt;
}

#endif

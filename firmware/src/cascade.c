/*
 * The cascade controller's step: the C port of src/ttt_sm/twin/_cascade.py,
 * operation for operation (see cascade.h and docs/model.md).
 */
#include "ttt_fw/cascade.h"

static ttt_real clip(ttt_real x, ttt_real lo, ttt_real hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

static ttt_real servo_duty_for_angle(ttt_real angle, const ttt_real *cg)
{
    ttt_real lo = cg[TTT_CG_SV_MIN], hi = cg[TTT_CG_SV_MAX];
    ttt_real a = clip(angle, lo, hi);
    ttt_real frac = (a - lo) / (hi - lo);
    return (cg[TTT_CG_SV_PMIN] + frac * (cg[TTT_CG_SV_PMAX] - cg[TTT_CG_SV_PMIN])) / cg[TTT_CG_SV_PERIOD];
}

/* Filters and cascade of drive d for one step (fig. 3.6); returns the duty the bridge gets now. */
static ttt_real control_drive(ttt_cascade *c, int d, int32_t count, int slow, ttt_real dt)
{
    const ttt_real *cp = c->cp[d];
    const ttt_real *cg = c->cg;
    ttt_real *cs = c->cs[d];
    int32_t mode = c->cm[d];
    ttt_real q_meas = (ttt_real)count * cp[TTT_CP_RPC] + cs[TTT_CS_OFFSET];
    /* speed from a filtered derivative of the encoder angle (no tachometer) */
    ttt_real w_raw = (q_meas - cs[TTT_CS_Q_PREV]) / dt;
    ttt_real w_prev, w_meas, r, v, u, duty, applied;
    int b = slow ? TTT_CG_SF_SLOW : TTT_CG_SF_NORMAL;
    cs[TTT_CS_Q_PREV] = q_meas;
    w_prev = cs[TTT_CS_W_MEAS];
    w_meas = w_prev + cp[TTT_CP_ALPHA_W] * (w_raw - w_prev);
    cs[TTT_CS_W_MEAS] = w_meas;
    /* second-order setpoint filter, exact discretisation (state: angle, rate) */
    r = cs[TTT_CS_R_F];
    v = cs[TTT_CS_R_FD];
    u = cs[TTT_CS_R_RAW];
    cs[TTT_CS_R_F] = cg[b] * r + cg[b + 1] * v + cg[b + 2] * u;
    cs[TTT_CS_R_FD] = cg[b + 3] * r + cg[b + 4] * v + cg[b + 5] * u;

    duty = TTT_R(0.0);
    if (mode == TTT_MODE_CLOSED) {
        /* outer loop: position PID -> speed setpoint, clamped to the drive's speed */
        ttt_real e = cs[TTT_CS_R_F] - q_meas;
        ttt_real wmax = cp[TTT_CP_WMAX];
        ttt_real i_pos = cs[TTT_CS_INT_POS] + cp[TTT_CP_KI_POS] * e * dt;
        ttt_real w_ff = cp[TTT_CP_KFF] * cs[TTT_CS_R_FD];
        ttt_real w_d = cp[TTT_CP_KD_POS] * (cs[TTT_CS_R_FD] - w_meas);
        ttt_real w_u = cp[TTT_CP_KP_POS] * e + i_pos + w_d + w_ff;
        ttt_real w_ref = clip(w_u, -wmax, wmax);
        ttt_real ew, i_spd, u_d, u_w;
        /* clamping anti-windup: keep the integral only if it does not push further into the clamp */
        if (w_ref == w_u || (w_u > wmax) != (e > TTT_R(0.0))) {
            cs[TTT_CS_INT_POS] = i_pos;
        }
        cs[TTT_CS_W_REF] = w_ref;
        /* inner loop: speed PID (derivative on the measurement) -> PWM duty */
        ew = w_ref - w_meas;
        i_spd = cs[TTT_CS_INT_SPD] + cp[TTT_CP_KI_SPD] * ew * dt;
        u_d = -cp[TTT_CP_KD_SPD] * (w_meas - w_prev) / dt;
        u_w = cp[TTT_CP_KP_SPD] * ew + i_spd + u_d;
        duty = clip(u_w, TTT_R(-1.0), TTT_R(1.0)); /* PWM saturation */
        if (duty == u_w || (u_w > TTT_R(1.0)) != (ew > TTT_R(0.0))) {
            cs[TTT_CS_INT_SPD] = i_spd;
        }
    } else {
        cs[TTT_CS_INT_POS] = TTT_R(0.0);
        cs[TTT_CS_INT_SPD] = TTT_R(0.0);
        cs[TTT_CS_W_REF] = TTT_R(0.0);
        if (mode == TTT_MODE_OPEN) {
            duty = clip(cs[TTT_CS_OPEN_DUTY], TTT_R(-1.0), TTT_R(1.0));
        }
    }
    /* one-sample computation delay: the bridge gets last step's command */
    applied = cs[TTT_CS_DUTY_CMD];
    cs[TTT_CS_DUTY_CMD] = duty;
    return applied;
}

int ttt_real_size(void)
{
    return (int)sizeof(ttt_real);
}

void ttt_cascade_init(ttt_cascade *c)
{
    int d, k;
    for (d = 0; d < TTT_DRIVES; d++) {
        for (k = 0; k < TTT_N_CP; k++) c->cp[d][k] = TTT_R(0.0);
        for (k = 0; k < TTT_N_CS; k++) c->cs[d][k] = TTT_R(0.0);
        c->cm[d] = TTT_MODE_CLOSED;
    }
    for (k = 0; k < TTT_N_CG; k++) c->cg[k] = TTT_R(0.0);
    for (k = 0; k < TTT_N_CGS; k++) c->cgs[k] = TTT_R(0.0);
    for (k = 0; k < TTT_N_ACT; k++) c->act[k] = TTT_R(0.0);
    /* NaN (0/0 without a library): the first step computes the servo's duty */
    {
        volatile ttt_real zero = TTT_R(0.0);
        c->cgs[TTT_CGS_SV_DUTY_OF] = zero / zero;
    }
}

void ttt_cascade_step(ttt_cascade *c, const int32_t counts[TTT_DRIVES])
{
    ttt_real dt = c->cg[TTT_CG_DT];
    int slow = c->cgs[TTT_CGS_FR_SW] > TTT_R(0.5);
    int d;
    ttt_real sv_set;
    for (d = 0; d < TTT_DRIVES; d++) {
        int32_t mode = c->cm[d];
        c->act[TTT_ACT_DUTY + d] = control_drive(c, d, counts[d], slow, dt);
        c->act[TTT_ACT_BRIDGE + d] = mode == TTT_MODE_OFF ? TTT_R(0.0) : TTT_R(1.0);
    }
    sv_set = c->cgs[TTT_CGS_SV_SET];
    if (sv_set != c->cgs[TTT_CGS_SV_DUTY_OF]) {
        c->cgs[TTT_CGS_SV_DUTY] = servo_duty_for_angle(sv_set, c->cg);
        c->cgs[TTT_CGS_SV_DUTY_OF] = sv_set;
    }
    c->act[TTT_ACT_SV_DUTY] = c->cgs[TTT_CGS_SV_DUTY];
}

void ttt_cascade_set_setpoints(ttt_cascade *c, const ttt_real q[4], int fr_sw)
{
    int d;
    for (d = 0; d < TTT_DRIVES; d++) c->cs[d][TTT_CS_R_RAW] = q[d];
    c->cgs[TTT_CGS_FR_SW] = fr_sw ? TTT_R(1.0) : TTT_R(0.0);
    c->cgs[TTT_CGS_SV_SET] = q[3];
}

void ttt_cascade_set_offset(ttt_cascade *c, int d, ttt_real offset)
{
    ttt_real *cs = c->cs[d];
    ttt_real shift = offset - cs[TTT_CS_OFFSET];
    cs[TTT_CS_OFFSET] = offset;
    cs[TTT_CS_R_RAW] += shift;
    cs[TTT_CS_R_F] += shift;
    cs[TTT_CS_Q_PREV] += shift;
}

void ttt_cascade_hold(ttt_cascade *c, int d, ttt_real q)
{
    ttt_real *cs = c->cs[d];
    cs[TTT_CS_R_RAW] = q;
    cs[TTT_CS_R_F] = q;
    cs[TTT_CS_R_FD] = TTT_R(0.0);
    cs[TTT_CS_Q_PREV] = q;
    cs[TTT_CS_W_MEAS] = TTT_R(0.0);
    cs[TTT_CS_INT_POS] = TTT_R(0.0);
    cs[TTT_CS_INT_SPD] = TTT_R(0.0);
}

void ttt_cascade_set_mode(ttt_cascade *c, int d, int32_t mode, ttt_real hold_q)
{
    if (mode == TTT_MODE_CLOSED && c->cm[d] != TTT_MODE_CLOSED) {
        ttt_cascade_hold(c, d, hold_q);
    }
    c->cm[d] = mode;
}

void ttt_cascade_set_open_duty(ttt_cascade *c, int d, ttt_real duty)
{
    c->cs[d][TTT_CS_OPEN_DUTY] = duty;
    c->cm[d] = TTT_MODE_OPEN;
}

ttt_real ttt_cascade_angle(const ttt_cascade *c, int d, int32_t count)
{
    return (ttt_real)count * c->cp[d][TTT_CP_RPC] + c->cs[d][TTT_CS_OFFSET];
}

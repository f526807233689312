/* The firmware's core: messages, states, watchdog (fw.h). */
#include "ttt_fw/fw.h"

static int finite(double v)
{
    return (v - v) == 0.0; /* NaN - NaN and inf - inf are NaN */
}

static void send(ttt_fw *fw, uint8_t type, const uint8_t *body, size_t n)
{
    uint8_t wire[TTT_MAX_ENCODED + 1];
    size_t len = ttt_frame_encode(type, fw->tx_seq, body, n, wire), i;
    if (len == 0 || fw->tx_len + len > sizeof fw->tx) {
        fw->tx_dropped++;
        return;
    }
    for (i = 0; i < len; i++) fw->tx[fw->tx_len + i] = wire[i];
    fw->tx_len += len;
    fw->tx_seq++;
}

static void reject(ttt_fw *fw, int reason)
{
    fw->rejections[reason]++;
    fw->last_reject = reason;
}

static void send_handshake(ttt_fw *fw)
{
    uint8_t b[TTT_BODY_HANDSHAKE];
    const ttt_board *bd = &fw->board;
    int d;
    b[TTT_HANDSHAKE_PROTOCOL] = TTT_PROTOCOL_VERSION;
    b[TTT_HANDSHAKE_FIRMWARE] = TTT_FW_VERSION_MAJOR;
    b[TTT_HANDSHAKE_FIRMWARE + 1] = TTT_FW_VERSION_MINOR;
    b[TTT_HANDSHAKE_FIRMWARE + 2] = TTT_FW_VERSION_PATCH;
    b[TTT_HANDSHAKE_DRIVES] = TTT_DRIVES;
    b[TTT_HANDSHAKE_REAL_SIZE] = (uint8_t)sizeof(ttt_real);
    ttt_put_u32(b + TTT_HANDSHAKE_CONTROL_PERIOD_US, bd->control_period_us);
    for (d = 0; d < TTT_DRIVES; d++) {
        uint8_t *drive = b + TTT_HANDSHAKE_DRIVE_STRIDE * d;
        ttt_put_f64(drive + TTT_HANDSHAKE_RAD_PER_COUNT, bd->rad_per_count[d]);
        ttt_put_f32(drive + TTT_HANDSHAKE_LIMIT_MIN_RAD, bd->limit_min_rad[d]);
        ttt_put_f32(drive + TTT_HANDSHAKE_LIMIT_MAX_RAD, bd->limit_max_rad[d]);
    }
    ttt_put_f32(b + TTT_HANDSHAKE_SERVO_MIN_RAD, bd->servo_min_rad);
    ttt_put_f32(b + TTT_HANDSHAKE_SERVO_MAX_RAD, bd->servo_max_rad);
    ttt_put_f32(b + TTT_HANDSHAKE_SERVO_SAFE_RAD, bd->servo_safe_rad);
    send(fw, TTT_MSG_HANDSHAKE, b, sizeof b);
}

static ttt_real *gains_block(ttt_fw *fw, uint8_t block, int *count)
{
    if (block < TTT_DRIVES) {
        *count = TTT_N_CP;
        return fw->cascade.cp[block];
    }
    *count = TTT_N_CG;
    return fw->cascade.cg;
}

static void send_gains(ttt_fw *fw, uint8_t block)
{
    uint8_t b[TTT_BODY_GAINS_GLOBAL];
    int count, k;
    const ttt_real *v = gains_block(fw, block, &count);
    b[TTT_GAINS_BLOCK] = block;
    for (k = 0; k < count; k++) ttt_put_f64(b + TTT_GAINS_VALUES + 8 * k, (double)v[k]);
    send(fw, TTT_MSG_GAINS_READBACK, b, TTT_GAINS_VALUES + 8 * (size_t)count);
}

static void send_heartbeat_reply(ttt_fw *fw, uint32_t token)
{
    uint8_t b[TTT_BODY_HEARTBEAT_REPLY];
    int r;
    ttt_put_u32(b + TTT_HEARTBEAT_REPLY_TOKEN, token);
    ttt_put_u32(b + TTT_HEARTBEAT_REPLY_STEP, fw->step);
    ttt_put_u32(b + TTT_HEARTBEAT_REPLY_FRAMES_OK, fw->frames_ok);
    ttt_put_u32(b + TTT_HEARTBEAT_REPLY_LOST, fw->rx_seq.lost);
    for (r = 0; r < TTT_N_REJ; r++) ttt_put_u32(b + TTT_HEARTBEAT_REPLY_REJECTIONS + 4 * r, fw->rejections[r]);
    send(fw, TTT_MSG_HEARTBEAT_REPLY, b, sizeof b);
}

static void send_status(ttt_fw *fw)
{
    uint8_t b[TTT_BODY_STATUS];
    const ttt_sensors *s = &fw->sensors;
    int d;
    uint8_t modes = 0;
    ttt_put_u32(b + TTT_STATUS_STEP, fw->step);
    b[TTT_STATUS_STATE] = fw->state;
    b[TTT_STATUS_INDEX] = s->index;
    for (d = 0; d < TTT_DRIVES; d++) {
        int mode = fw->cascade.cm[d] & ((1 << TTT_STATUS_MODE_BITS) - 1);
        modes = (uint8_t)(modes | (mode << (TTT_STATUS_MODE_BITS * d)));
    }
    b[TTT_STATUS_MODES] = modes;
    for (d = 0; d < TTT_DRIVES; d++) {
        float ma = s->current_a[d] * 1000.0f;
        int32_t i = !finite((double)ma) ? 0 : ma > 32767.0f ? 32767 : ma < -32768.0f ? -32768 : (int32_t)ma;
        ttt_put_u32(b + TTT_STATUS_COUNTS + 4 * d, (uint32_t)s->counts[d]);
        ttt_put_u32(b + TTT_STATUS_INDEX_COUNT + 4 * d, (uint32_t)s->index_count[d]);
        ttt_put_u16(b + TTT_STATUS_INDEX_EDGES + 2 * d, s->index_edges[d]);
        ttt_put_u16(b + TTT_STATUS_CURRENT_MA + 2 * d, (uint16_t)(int16_t)i);
    }
    ttt_put_u16(b + TTT_STATUS_SERVO_ADC, s->servo_adc); /* raw counts: the PC calibrates (docs/hardware.md) */
    send(fw, TTT_MSG_STATUS, b, sizeof b);
}

/* Every drive that has power holds the angle it is at; the pen goes to its safe angle. */
static void hold_here(ttt_fw *fw)
{
    int d;
    for (d = 0; d < TTT_DRIVES; d++) {
        ttt_real q = ttt_cascade_angle(&fw->cascade, d, fw->sensors.counts[d]);
        if (fw->cascade.cm[d] != TTT_MODE_OFF) {
            fw->cascade.cm[d] = TTT_MODE_CLOSED;
            ttt_cascade_hold(&fw->cascade, d, q);
        }
    }
}

static void start(ttt_fw *fw)
{
    int d;
    for (d = 0; d < TTT_DRIVES; d++) {
        ttt_real q = ttt_cascade_angle(&fw->cascade, d, fw->sensors.counts[d]);
        fw->cascade.cm[d] = TTT_MODE_CLOSED;
        ttt_cascade_hold(&fw->cascade, d, q);
    }
    fw->state = TTT_STATE_RUNNING;
    fw->last_setpoint_step = fw->step;
    send_status(fw); /* the PC learns at once that the drives run, and from which step */
}

/* Whether one block of gains is sane: speeds, filter shares and periods positive and within bounds
 * (every value already finite and within +-TTT_GAIN_MAX).  A control step of 0 divides by zero;
 * one of seconds is no control loop. */
static int gains_in_range(uint8_t block, const double *v)
{
    if (block < TTT_DRIVES)
        return v[TTT_CP_RPC] != 0.0 && v[TTT_CP_RPC] < 1.0 && v[TTT_CP_RPC] > -1.0
            && v[TTT_CP_WMAX] > 0.0 && v[TTT_CP_ALPHA_W] > 0.0 && v[TTT_CP_ALPHA_W] <= 1.0;
    return v[TTT_CG_DT] >= TTT_DT_MIN_S && v[TTT_CG_DT] <= TTT_DT_MAX_S
        && v[TTT_CG_SV_MIN] < v[TTT_CG_SV_MAX]
        && v[TTT_CG_SV_PMIN] > 0.0 && v[TTT_CG_SV_PMAX] > v[TTT_CG_SV_PMIN]
        && v[TTT_CG_SV_PERIOD] >= v[TTT_CG_SV_PMAX] && v[TTT_CG_SV_PERIOD] <= TTT_SV_PERIOD_MAX_S;
}

/* Whether setpoint k (drives 0..2: encoder coordinates, rad; 3: the servo, rad) is one the arm can
 * take.  The servo's must lie in its range.  A drive's coordinates are the joint's once its offset
 * is set, and differ from them by less than the joint's span before (it starts between its
 * stops): so a setpoint more than one span beyond a limit is never a place the joint can reach. */
static int setpoint_in_range(const ttt_board *bd, int k, float v)
{
    float span;
    if (k == 3) return v >= bd->servo_min_rad && v <= bd->servo_max_rad;
    span = bd->limit_max_rad[k] - bd->limit_min_rad[k];
    return v >= bd->limit_min_rad[k] - span && v <= bd->limit_max_rad[k] + span;
}

/* Act on one decoded frame whose sequence number was accepted; returns a rejection reason or -1. */
static int handle(ttt_fw *fw, uint8_t type, const uint8_t *b, size_t n)
{
    int d, k, count;
    (void)n;
    switch (type) {
    case TTT_MSG_HELLO:
        send_handshake(fw);
        return -1;
    case TTT_MSG_GAINS: {
        uint8_t block = b[TTT_GAINS_BLOCK];
        ttt_real *dst;
        double v[TTT_N_CG];
        if (block >= TTT_GAINS_BLOCKS) return TTT_REJ_VALUE;
        if (fw->state == TTT_STATE_RUNNING) return TTT_REJ_REFUSED;
        dst = gains_block(fw, block, &count);
        for (k = 0; k < count; k++) {
            v[k] = ttt_get_f64(b + TTT_GAINS_VALUES + 8 * k);
            if (!finite(v[k]) || v[k] > TTT_GAIN_MAX || v[k] < -TTT_GAIN_MAX) return TTT_REJ_VALUE;
        }
        if (!gains_in_range(block, v)) return TTT_REJ_VALUE;
        for (k = 0; k < count; k++) dst[k] = (ttt_real)v[k];
        fw->gains_loaded = (uint8_t)(fw->gains_loaded | (1u << block));
        send_gains(fw, block);
        return -1;
    }
    case TTT_MSG_GAINS_READ:
        if (b[TTT_GAINS_READ_BLOCK] >= TTT_GAINS_BLOCKS) return TTT_REJ_VALUE;
        send_gains(fw, b[TTT_GAINS_READ_BLOCK]);
        return -1;
    case TTT_MSG_SETPOINTS: {
        uint32_t at = ttt_get_u32(b + TTT_SETPOINTS_STEP);
        ttt_real q[4];
        if (fw->state != TTT_STATE_RUNNING) return TTT_REJ_REFUSED;
        if ((uint32_t)(fw->step - at) < 0x80000000u && fw->step - at > fw->board.late_steps) return TTT_REJ_LATE;
        for (k = 0; k < 4; k++) {
            float v = ttt_get_f32(b + TTT_SETPOINTS_Q + 4 * k);
            if (!finite((double)v) || !setpoint_in_range(&fw->board, k, v)) return TTT_REJ_VALUE;
            q[k] = (ttt_real)v;
        }
        ttt_cascade_set_setpoints(&fw->cascade, q, b[TTT_SETPOINTS_FLAGS] & TTT_SETPOINTS_FLAG_FR_SW);
        fw->last_setpoint_step = fw->step;
        fw->setpoints_ok++;
        return -1;
    }
    case TTT_MSG_HEARTBEAT:
        send_heartbeat_reply(fw, ttt_get_u32(b + TTT_HEARTBEAT_TOKEN));
        return -1;
    case TTT_MSG_DRIVE: {
        double v = ttt_get_f64(b + TTT_DRIVE_VALUE);
        uint8_t op = b[TTT_DRIVE_OP];
        ttt_real q;
        d = b[TTT_DRIVE_DRIVE];
        if (d >= TTT_DRIVES || op > TTT_OP_OFFSET || !finite(v)) return TTT_REJ_VALUE;
        if (fw->state != TTT_STATE_RUNNING) return TTT_REJ_REFUSED;
        q = ttt_cascade_angle(&fw->cascade, d, fw->sensors.counts[d]);
        switch (op) {
        case TTT_OP_OFF: ttt_cascade_set_mode(&fw->cascade, d, TTT_MODE_OFF, q); break;
        case TTT_OP_CLOSED: ttt_cascade_set_mode(&fw->cascade, d, TTT_MODE_CLOSED, q); break;
        case TTT_OP_OPEN: ttt_cascade_set_open_duty(&fw->cascade, d, (ttt_real)v); break;
        default: ttt_cascade_set_offset(&fw->cascade, d, (ttt_real)v); break;
        }
        return -1;
    }
    case TTT_MSG_START:
        if (fw->gains_loaded != (1u << TTT_GAINS_BLOCKS) - 1u) return TTT_REJ_REFUSED;
        start(fw);
        return -1;
    default:
        return TTT_REJ_UNKNOWN_TYPE; /* a firmware -> PC type sent to the firmware */
    }
}

void ttt_fw_init(ttt_fw *fw, const ttt_board *board)
{
    int r;
    fw->board = *board;
    ttt_cascade_init(&fw->cascade);
    for (r = 0; r < TTT_DRIVES; r++) {
        fw->cascade.cm[r] = TTT_MODE_OFF;
        fw->sensors.counts[r] = 0;
        fw->sensors.index_count[r] = 0;
        fw->sensors.index_edges[r] = 0;
        fw->sensors.current_a[r] = 0.0f;
    }
    fw->sensors.index = 0;
    fw->cascade.cgs[TTT_CGS_SV_SET] = (ttt_real)board->servo_safe_rad;
    ttt_rx_init(&fw->rx);
    ttt_seq_reset(&fw->rx_seq);
    fw->tx_seq = 0;
    fw->state = TTT_STATE_IDLE;
    fw->gains_loaded = 0;
    fw->safe_reason = 0;
    fw->step = 0;
    fw->last_setpoint_step = 0;
    fw->setpoints_ok = 0;
    fw->frames_ok = 0;
    for (r = 0; r < TTT_N_REJ; r++) fw->rejections[r] = 0;
    fw->last_reject = -1;
    fw->tx_len = 0;
    fw->tx_dropped = 0;
}

void ttt_fw_rx(ttt_fw *fw, const uint8_t *data, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        int got = ttt_rx_byte(&fw->rx, data[i]);
        int reason;
        if (got == TTT_RX_REJECTED) {
            reject(fw, fw->rx.reason);
            continue;
        }
        if (got != TTT_RX_FRAME) continue;
        if (fw->rx.type >= TTT_FIRST_TO_PC) { /* a firmware -> PC type: not for us, its number not taken */
            reject(fw, TTT_REJ_UNKNOWN_TYPE);
            continue;
        }
        if (fw->rx.type == TTT_MSG_HELLO) ttt_seq_reset(&fw->rx_seq); /* a new session */
        reason = ttt_seq_accept(&fw->rx_seq, fw->rx.seq);
        if (reason == 0) reason = handle(fw, fw->rx.type, fw->rx.body, fw->rx.body_len);
        if (reason >= 0) {
            reject(fw, reason);
        } else {
            fw->frames_ok++;
        }
    }
}

size_t ttt_fw_tx(ttt_fw *fw, uint8_t *out, size_t cap)
{
    size_t n = fw->tx_len < cap ? fw->tx_len : cap, i;
    for (i = 0; i < n; i++) out[i] = fw->tx[i];
    for (i = n; i < fw->tx_len; i++) fw->tx[i - n] = fw->tx[i];
    fw->tx_len -= n;
    return n;
}

void ttt_fw_sense(ttt_fw *fw, const ttt_sensors *in) { fw->sensors = *in; }

void ttt_fw_control_step(ttt_fw *fw, const ttt_sensors *in)
{
    int k;
    fw->sensors = *in;
    if (fw->state == TTT_STATE_RUNNING && fw->step - fw->last_setpoint_step >= fw->board.watchdog_steps) {
        fw->state = TTT_STATE_SAFE_STOP;
        fw->safe_reason = 1;
        hold_here(fw);
        fw->cascade.cgs[TTT_CGS_SV_SET] = (ttt_real)fw->board.servo_safe_rad;
    }
    if (fw->state == TTT_STATE_IDLE) {
        for (k = 0; k < TTT_N_ACT; k++) fw->cascade.act[k] = TTT_R(0.0); /* bridges off, no servo pulse */
    } else {
        ttt_cascade_step(&fw->cascade, in->counts);
    }
    fw->step++;
    if (fw->board.status_every != 0 && fw->step % fw->board.status_every == 0) send_status(fw);
}

size_t ttt_fw_size(void) { return sizeof(ttt_fw); }
ttt_cascade *ttt_fw_cascade(ttt_fw *fw) { return &fw->cascade; }
uint8_t ttt_fw_state(const ttt_fw *fw) { return fw->state; }
uint32_t ttt_fw_frames_ok(const ttt_fw *fw) { return fw->frames_ok; }
uint32_t ttt_fw_rejections(const ttt_fw *fw, int reason)
{
    return reason >= 0 && reason < TTT_N_REJ ? fw->rejections[reason] : 0u;
}
uint32_t ttt_fw_lost(const ttt_fw *fw) { return fw->rx_seq.lost; }
uint32_t ttt_fw_step(const ttt_fw *fw) { return fw->step; }
uint32_t ttt_fw_last_setpoint_step(const ttt_fw *fw) { return fw->last_setpoint_step; }
uint32_t ttt_fw_setpoints_ok(const ttt_fw *fw) { return fw->setpoints_ok; }

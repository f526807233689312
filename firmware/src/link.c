/* The serial link's frames: CRC, COBS, the stream decoder, sequence numbers (link.h). */
#include "ttt_fw/link.h"

uint16_t ttt_crc16(const uint8_t *data, size_t n)
{
    uint16_t crc = 0xFFFFu;
    size_t i;
    int b;
    for (i = 0; i < n; i++) {
        crc = (uint16_t)(crc ^ (uint16_t)(data[i] << 8));
        for (b = 0; b < 8; b++) {
            uint16_t shifted = (uint16_t)((unsigned)crc << 1);
            crc = (crc & 0x8000u) != 0u ? (uint16_t)(shifted ^ 0x1021u) : shifted;
        }
    }
    return crc;
}

size_t ttt_cobs_encode(const uint8_t *in, size_t n, uint8_t *out)
{
    size_t read = 0, write = 1, code_at = 0;
    uint8_t code = 1;
    while (read < n) {
        if (in[read] == 0) {
            out[code_at] = code;
            code_at = write++;
            code = 1;
        } else {
            out[write++] = in[read];
            code++;
            if (code == 0xFF) {
                out[code_at] = code;
                code_at = write++;
                code = 1;
            }
        }
        read++;
    }
    out[code_at] = code;
    return write;
}

int ttt_cobs_decode(const uint8_t *in, size_t n, uint8_t *out)
{
    size_t read = 0, write = 0;
    while (read < n) {
        uint8_t code = in[read++];
        uint8_t i;
        if (code == 0 || read + code - 1u > n) return -1;
        for (i = 1; i < code; i++) {
            if (in[read] == 0) return -1;
            out[write++] = in[read++];
        }
        if (code != 0xFF && read != n) out[write++] = 0;
    }
    return (int)write;
}

int ttt_body_length(uint8_t type)
{
    switch (type) {
    case TTT_MSG_HELLO: return TTT_BODY_HELLO;
    case TTT_MSG_GAINS: return -2; /* variable: see gains_length */
    case TTT_MSG_GAINS_READ: return TTT_BODY_GAINS_READ;
    case TTT_MSG_SETPOINTS: return TTT_BODY_SETPOINTS;
    case TTT_MSG_HEARTBEAT: return TTT_BODY_HEARTBEAT;
    case TTT_MSG_DRIVE: return TTT_BODY_DRIVE;
    case TTT_MSG_START: return TTT_BODY_START;
    case TTT_MSG_HANDSHAKE: return TTT_BODY_HANDSHAKE;
    case TTT_MSG_GAINS_READBACK: return -2;
    case TTT_MSG_STATUS: return TTT_BODY_STATUS;
    case TTT_MSG_HEARTBEAT_REPLY: return TTT_BODY_HEARTBEAT_REPLY;
    default: return -1;
    }
}

size_t ttt_frame_encode(uint8_t type, uint16_t seq, const uint8_t *body, size_t n, uint8_t *out)
{
    uint8_t frame[TTT_MAX_FRAME];
    size_t i, len;
    uint16_t crc;
    if (n > TTT_MAX_BODY) return 0;
    frame[TTT_FRAME_TYPE] = type;
    ttt_put_u16(frame + TTT_FRAME_SEQ, seq);
    for (i = 0; i < n; i++) frame[TTT_HEADER + i] = body[i];
    crc = ttt_crc16(frame, TTT_HEADER + n);
    frame[TTT_HEADER + n] = (uint8_t)(crc >> 8);
    frame[TTT_HEADER + n + 1] = (uint8_t)(crc & 0xFFu);
    len = ttt_cobs_encode(frame, TTT_HEADER + n + TTT_CRC, out);
    out[len] = 0;
    return len + 1;
}

void ttt_rx_init(ttt_rx *rx)
{
    rx->len = 0;
    rx->overflow = 0;
    rx->type = 0;
    rx->seq = 0;
    rx->body = rx->frame + TTT_HEADER;
    rx->body_len = 0;
    rx->reason = 0;
}

/* The body length a GAINS or GAINS_READBACK body must have for its block byte (a body without
 * one is cut short: shorter than either). */
static int gains_length(const uint8_t *body, size_t n)
{
    if (n < TTT_GAINS_VALUES) return TTT_BODY_GAINS_DRIVE;
    return body[TTT_GAINS_BLOCK] == TTT_GAINS_BLOCK_GLOBAL ? TTT_BODY_GAINS_GLOBAL : TTT_BODY_GAINS_DRIVE;
}

static int judge(ttt_rx *rx)
{
    int n, expected;
    uint16_t crc;
    if (rx->overflow) return TTT_REJ_OVERLONG;
    n = ttt_cobs_decode(rx->buf, rx->len, rx->frame);
    if (n < 0) return TTT_REJ_COBS;
    if (n < TTT_HEADER + TTT_CRC) return TTT_REJ_SHORT;
    crc = (uint16_t)((rx->frame[n - 2] << 8) | rx->frame[n - 1]);
    if (crc != ttt_crc16(rx->frame, (size_t)n - TTT_CRC)) return TTT_REJ_CRC;
    rx->type = rx->frame[TTT_FRAME_TYPE];
    rx->seq = ttt_get_u16(rx->frame + TTT_FRAME_SEQ);
    rx->body = rx->frame + TTT_HEADER;
    rx->body_len = (size_t)n - TTT_HEADER - TTT_CRC;
    expected = ttt_body_length(rx->type);
    if (expected == -1) return TTT_REJ_UNKNOWN_TYPE;
    if (expected == -2) expected = gains_length(rx->body, rx->body_len);
    if (rx->body_len < (size_t)expected) return TTT_REJ_PARTIAL;
    if (rx->body_len > (size_t)expected) return TTT_REJ_LENGTH;
    return -1;
}

int ttt_rx_byte(ttt_rx *rx, uint8_t byte)
{
    if (byte != 0) {
        if (rx->len < sizeof rx->buf) {
            rx->buf[rx->len++] = byte;
        } else {
            rx->overflow = 1;
        }
        return TTT_RX_NONE;
    }
    if (rx->len == 0 && !rx->overflow) return TTT_RX_NONE; /* an empty frame: a resync delimiter */
    rx->reason = judge(rx);
    rx->len = 0;
    rx->overflow = 0;
    if (rx->reason >= 0) return TTT_RX_REJECTED;
    rx->reason = 0;
    return TTT_RX_FRAME;
}

void ttt_seq_reset(ttt_seq *s)
{
    s->have = 0;
    s->last = 0;
    s->lost = 0;
}

int ttt_seq_accept(ttt_seq *s, uint16_t seq)
{
    uint16_t delta = (uint16_t)(seq - s->last);
    if (s->have) {
        if (delta == 0) return TTT_REJ_DUPLICATE;
        if (delta >= TTT_SEQ_BEHIND) return TTT_REJ_OUT_OF_ORDER;
        s->lost += (uint32_t)(delta - 1u);
    }
    s->have = 1;
    s->last = seq;
    return 0;
}

void ttt_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

void ttt_put_u32(uint8_t *p, uint32_t v)
{
    int i;
    for (i = 0; i < 4; i++) p[i] = (uint8_t)((v >> (8 * i)) & 0xFFu);
}

void ttt_put_f32(uint8_t *p, float v)
{
    union { float f; uint32_t u; } x;
    x.f = v;
    ttt_put_u32(p, x.u);
}

void ttt_put_f64(uint8_t *p, double v)
{
    union { double f; uint32_t u[2]; uint8_t b[8]; } x;
    uint16_t probe = 1;
    int i;
    x.f = v;
    if (*(uint8_t *)&probe == 1) { /* little-endian CPU */
        for (i = 0; i < 8; i++) p[i] = x.b[i];
    } else {
        for (i = 0; i < 8; i++) p[i] = x.b[7 - i];
    }
}

uint16_t ttt_get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

uint32_t ttt_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

float ttt_get_f32(const uint8_t *p)
{
    union { float f; uint32_t u; } x;
    x.u = ttt_get_u32(p);
    return x.f;
}

double ttt_get_f64(const uint8_t *p)
{
    union { double f; uint8_t b[8]; } x;
    uint16_t probe = 1;
    int i;
    if (*(uint8_t *)&probe == 1) {
        for (i = 0; i < 8; i++) x.b[i] = p[i];
    } else {
        for (i = 0; i < 8; i++) x.b[7 - i] = p[i];
    }
    return x.f;
}

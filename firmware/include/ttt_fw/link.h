/*
 * The serial link's frames (docs/hardware.md, "The link protocol"):
 * COBS-encoded frames, each closed by a 0x00 byte; inside, the type, a
 * 16-bit sequence number, the body and a CRC-16/CCITT-FALSE.
 *
 * Everything here is pure: no I/O, no clock, no heap.  The byte stream is
 * fed one byte at a time to a ttt_rx; it answers with a frame or with the
 * reason the bytes were rejected.
 *
 * The protocol's numbers (the version, the framing's sizes, the message
 * types TTT_MSG_*, the rejection reasons TTT_REJ_*) and each body's length
 * and field offsets are in protocol.h, generated from the PC's tables
 * (src/ttt_sm/hardware/link/protocol.py).
 */
#ifndef TTT_FW_LINK_H
#define TTT_FW_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "protocol.h"

/* CRC-16/CCITT-FALSE: polynomial 0x1021, init 0xFFFF, no reflection, no final xor ("123456789" -> 0x29B1). */
uint16_t ttt_crc16(const uint8_t *data, size_t n);

/* COBS: encode n bytes into out (room for n + n/254 + 1); returns the encoded length (no 0x00 added). */
size_t ttt_cobs_encode(const uint8_t *in, size_t n, uint8_t *out);
/* Decode n COBS bytes (no 0x00) into out (room for n); returns the decoded length, or -1 if invalid. */
int ttt_cobs_decode(const uint8_t *in, size_t n, uint8_t *out);

/* The expected body length of a message type, or -1 for an unknown type. */
int ttt_body_length(uint8_t type);

/* Build a whole wire frame (COBS + the closing 0x00) into out (room for TTT_MAX_ENCODED + 1);
 * returns its length, or 0 if the body is too long. */
size_t ttt_frame_encode(uint8_t type, uint16_t seq, const uint8_t *body, size_t n, uint8_t *out);

/* The stream decoder. */
typedef struct ttt_rx {
    uint8_t buf[TTT_MAX_ENCODED];
    size_t len;
    int overflow;
    /* the last frame decoded (valid after TTT_RX_FRAME) */
    uint8_t frame[TTT_MAX_ENCODED];
    uint8_t type;
    uint16_t seq;
    const uint8_t *body;
    size_t body_len;
    int reason; /* the last rejection's reason (valid after TTT_RX_REJECTED) */
} ttt_rx;

#define TTT_RX_NONE 0      /* byte taken, nothing complete */
#define TTT_RX_FRAME 1     /* a frame is in rx->type, seq, body */
#define TTT_RX_REJECTED 2  /* the bytes up to this 0x00 were rejected: rx->reason */

void ttt_rx_init(ttt_rx *rx);
int ttt_rx_byte(ttt_rx *rx, uint8_t byte);

/* Sequence numbers of one direction: duplicates and frames from the past are refused. */
typedef struct ttt_seq {
    int have;      /* 0 until the first frame */
    uint16_t last;
    uint32_t lost; /* frames skipped over (gaps) */
} ttt_seq;

void ttt_seq_reset(ttt_seq *s);
/* 0: accepted (s->last updated, gaps added to lost); else TTT_REJ_DUPLICATE or TTT_REJ_OUT_OF_ORDER. */
int ttt_seq_accept(ttt_seq *s, uint16_t seq);

/* Little-endian fields, byte by byte (the same on any CPU). */
void ttt_put_u16(uint8_t *p, uint16_t v);
void ttt_put_u32(uint8_t *p, uint32_t v);
void ttt_put_f32(uint8_t *p, float v);
void ttt_put_f64(uint8_t *p, double v);
uint16_t ttt_get_u16(const uint8_t *p);
uint32_t ttt_get_u32(const uint8_t *p);
float ttt_get_f32(const uint8_t *p);
double ttt_get_f64(const uint8_t *p);

#endif

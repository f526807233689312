/*
 * The serial link's frames (docs/hardware.md, "The link protocol"):
 * COBS-encoded frames, each closed by a 0x00 byte; inside, the type, a
 * 16-bit sequence number, the body and a CRC-16/CCITT-FALSE.
 *
 * Everything here is pure: no I/O, no clock, no heap.  The byte stream is
 * fed one byte at a time to a ttt_rx; it answers with a frame or with the
 * reason the bytes were rejected.
 */
#ifndef TTT_FW_LINK_H
#define TTT_FW_LINK_H

#include <stddef.h>
#include <stdint.h>

#define TTT_PROTOCOL_VERSION 2

#define TTT_HEADER 3                              /* type, seq (u16 LE) */
#define TTT_CRC 2                                 /* CRC-16/CCITT-FALSE, MSB first */
#define TTT_MAX_BODY 160
#define TTT_MAX_FRAME (TTT_HEADER + TTT_MAX_BODY + TTT_CRC)
#define TTT_MAX_ENCODED (TTT_MAX_FRAME + TTT_MAX_FRAME / 254 + 1) /* COBS overhead, without the 0x00 */

/* message types: PC -> firmware below 0x80, firmware -> PC from 0x80 */
#define TTT_MSG_HELLO 0x01
#define TTT_MSG_GAINS 0x02
#define TTT_MSG_GAINS_READ 0x03
#define TTT_MSG_SETPOINTS 0x04
#define TTT_MSG_HEARTBEAT 0x05
#define TTT_MSG_DRIVE 0x06
#define TTT_MSG_START 0x07
#define TTT_MSG_HANDSHAKE 0x81
#define TTT_MSG_GAINS_READBACK 0x82
#define TTT_MSG_STATUS 0x85
#define TTT_MSG_HEARTBEAT_REPLY 0x86

/* rejection reasons (the same numbers on both sides of the link) */
#define TTT_REJ_COBS 0          /* not valid COBS */
#define TTT_REJ_CRC 1           /* CRC mismatch */
#define TTT_REJ_SHORT 2         /* fewer bytes than a header and a CRC */
#define TTT_REJ_OVERLONG 3      /* no 0x00 within the longest frame */
#define TTT_REJ_UNKNOWN_TYPE 4  /* no such message type */
#define TTT_REJ_PARTIAL 5       /* body shorter than its type's: a frame cut short */
#define TTT_REJ_LENGTH 6        /* body longer than its type's */
#define TTT_REJ_DUPLICATE 7     /* sequence number already seen */
#define TTT_REJ_OUT_OF_ORDER 8  /* sequence number behind the last one */
#define TTT_REJ_LATE 9          /* setpoints for a step already past */
#define TTT_REJ_REFUSED 10      /* valid, but not in this state (setpoints before START, gains while running) */
#define TTT_REJ_VALUE 11        /* a field out of range (drive, block, op, non-finite, a setpoint, gain or period beyond its range) */
#define TTT_N_REJ 12

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

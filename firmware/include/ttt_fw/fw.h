/*
 * The firmware's core: the link, the cascade and the watchdog, without a
 * board.  A board layer reads its sensors into a ttt_sensors, calls
 * ttt_fw_control_step() at the control rate, writes fw->cascade.act to the
 * H-bridges and the servo, feeds received bytes to ttt_fw_rx() and sends
 * what ttt_fw_tx() hands out (docs/hardware.md).
 *
 * States: IDLE after power-on (bridges off, no servo pulse; gains may be
 * downloaded), RUNNING after START (the cascade follows the setpoints),
 * SAFE_STOP when setpoints stopped arriving for board.watchdog_steps
 * control steps (each powered drive holds where it is, the pen goes to
 * board.servo_safe_rad) until the next START.  Their numbers (TTT_STATE_*),
 * the DRIVE operations (TTT_OP_*) and the gains blocks are in protocol.h.
 */
#ifndef TTT_FW_FW_H
#define TTT_FW_FW_H

#include <stddef.h>
#include <stdint.h>

#include "cascade.h"
#include "link.h"
#include "protocol.h"
#include "structs.h" /* ttt_board, ttt_sensors (and ttt_cascade), generated */

#define TTT_FW_VERSION_MAJOR 0
#define TTT_FW_VERSION_MINOR 2
#define TTT_FW_VERSION_PATCH 0

#define TTT_TX_CAP 1024

/* What GAINS may carry (checked in fw.c, rejected as TTT_REJ_VALUE; docs/hardware.md): no gain or
 * coefficient beyond +-TTT_GAIN_MAX, a control step in [TTT_DT_MIN_S, TTT_DT_MAX_S], a servo PWM
 * period up to TTT_SV_PERIOD_MAX_S (protocol.h: the bound of the PC's parameter files). */
#define TTT_GAIN_MAX 1.0e6
#define TTT_DT_MIN_S 1.0e-5
#define TTT_DT_MAX_S 0.1

/* The firmware's state.  Written here by hand, unlike ttt_board and ttt_sensors
 * (structs.h, generated with the PC's ctypes Structures from one table): the PC
 * never sees its layout, it allocates ttt_fw_size() bytes and reads them through
 * the functions at the end of this file. */
typedef struct ttt_fw {
    ttt_board board;
    ttt_cascade cascade;
    ttt_sensors sensors;      /* the last control step's */
    ttt_rx rx;
    ttt_seq rx_seq;
    uint16_t tx_seq;
    uint8_t state;
    uint8_t gains_loaded;     /* bit b: block b received */
    uint8_t safe_reason;      /* why the last SAFE_STOP: 1 watchdog */
    uint32_t step;            /* control steps since power-on */
    uint32_t last_setpoint_step;
    uint32_t setpoints_ok;    /* SETPOINTS frames acted on */
    uint32_t frames_ok;
    uint32_t rejections[TTT_N_REJ];
    int last_reject;          /* the last rejection's reason, -1 if none */
    uint8_t tx[TTT_TX_CAP];
    size_t tx_len;
    uint32_t tx_dropped;      /* frames that found the transmit buffer full */
} ttt_fw;

void ttt_fw_init(ttt_fw *fw, const ttt_board *board);
/* Received bytes, any chunking: frames are acted on, everything else counted and rejected. */
void ttt_fw_rx(ttt_fw *fw, const uint8_t *data, size_t n);
/* Up to cap bytes to send; returns how many were copied to out. */
size_t ttt_fw_tx(ttt_fw *fw, uint8_t *out, size_t cap);
/* One control step: the watchdog, the cascade (fw->cascade.act out), a STATUS when due. */
void ttt_fw_control_step(ttt_fw *fw, const ttt_sensors *in);
/* Take the sensor readings without a control step: what the next STATUS
 * reports and START holds from.  A board steps at the control rate from
 * power-on, so its readings are always fresh; an emulator whose clock the PC
 * gates runs no step before START, and calls this instead. */
void ttt_fw_sense(ttt_fw *fw, const ttt_sensors *in);



/* For bindings and board layers that do not see the struct's layout. */
size_t ttt_fw_size(void);
ttt_cascade *ttt_fw_cascade(ttt_fw *fw);
uint8_t ttt_fw_state(const ttt_fw *fw);
uint32_t ttt_fw_frames_ok(const ttt_fw *fw);
uint32_t ttt_fw_rejections(const ttt_fw *fw, int reason);
uint32_t ttt_fw_lost(const ttt_fw *fw);
uint32_t ttt_fw_step(const ttt_fw *fw);
uint32_t ttt_fw_last_setpoint_step(const ttt_fw *fw);
uint32_t ttt_fw_setpoints_ok(const ttt_fw *fw);
#endif

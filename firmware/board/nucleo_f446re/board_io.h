/*
 * The board layer's arithmetic, without a board: what the reference build's
 * sketch (nucleo_f446re.ino) does with its timers, pins and ADC, in portable
 * C99 so that it is compiled and tested on the PC (tests/hardware/
 * test_board_io.py) like the firmware's core.  Nothing here touches a
 * register: the sketch reads the hardware, calls these, writes the results.
 */
#ifndef TTT_BOARD_IO_H
#define TTT_BOARD_IO_H

#include <stdint.h>

#include "ttt_fw/fw.h"

/* A quadrature encoder counted by a 16-bit hardware timer, unwrapped to 32 bits. */
typedef struct ttt_bio_encoder {
    uint16_t last;  /* the timer's counter at the last read */
    int32_t count;  /* counts since power-on */
} ttt_bio_encoder;

/* The counter read at power-on is the zero (counts are relative to power-on, as the PC expects). */
void ttt_bio_encoder_init(ttt_bio_encoder *e, uint16_t timer_count);
/* Read it at least every 32767 counts (at 1 kHz: far above any motor speed). */
int32_t ttt_bio_encoder_update(ttt_bio_encoder *e, uint16_t timer_count);

/* An index switch: its level, and the count latched at each edge (either direction). */
typedef struct ttt_bio_index {
    uint8_t level;
    int32_t latched;
    uint16_t edges;
} ttt_bio_index;

void ttt_bio_index_init(ttt_bio_index *ix, int level);
/* `count_at_edge` is the encoder count captured when the edge came (an interrupt, or this step's count). */
void ttt_bio_index_update(ttt_bio_index *ix, int level, int32_t count_at_edge);

/* One H-bridge in phase/enable mode (DRV8874 PH/EN): the PWM compare value, the direction, the sleep pin. */
typedef struct ttt_bio_bridge {
    uint32_t compare;  /* 0 .. pwm_top */
    uint8_t phase;     /* 1: forward (duty > 0) */
    uint8_t awake;     /* 0: the bridge's outputs off (nSLEEP low) */
} ttt_bio_bridge;

ttt_bio_bridge ttt_bio_bridge_command(ttt_real duty, ttt_real bridge_on, uint32_t pwm_top);

/* The servo's pulse as a timer compare value: its duty (0..1, act[TTT_ACT_SV_DUTY]) of a period of
 * period_ticks; 0 (no pulse) for a duty that is not a number (before the firmware computed one). */
uint32_t ttt_bio_servo_compare(ttt_real duty, uint32_t period_ticks);

/* A motor current from the DRV8874's IPROPI voltage: adc of adc_full counts at vref volts, across
 * r_ipropi ohms, a_ipropi amps out per amp in (450e-6); signed by the bridge's direction. */
float ttt_bio_current_a(uint16_t adc, uint16_t adc_full, float vref, float r_ipropi, float a_ipropi, int phase);

/* The pen servo's feedback reading: the mean of n (1..16) conversions of its wiper, rounded (ADC counts).
 * The PC turns it into an angle with its two-point calibration ([servo] of the parameter file). */
uint16_t ttt_bio_servo_feedback(const uint16_t *samples, int n);

#endif

/*
 * The cascade controller of the three DC drives and the pen servo's PWM:
 * one control step per call (the thesis "Design of application for educational model of manipulator
 * with three degrees of freedom", section 3.2,
 * fig. 3.6), encoder counts in, H-bridge duties, bridge on/off flags and
 * the servo's duty out.
 *
 * This is the C port of the PC's compiled step (src/ttt_sm/twin/_cascade.py)
 * with the same memory layout (docs/model.md, "The controller step"):
 * the same blocks, the same index names, the same operations in the same
 * order.  No heap, no library call; the caller owns the struct.
 *
 * Drives are indexed 0..2 here (drive 1 of the thesis is index 0).
 */
#ifndef TTT_FW_CASCADE_H
#define TTT_FW_CASCADE_H

#include <stdint.h>

#include "real.h"

#define TTT_DRIVES 3

/* per-drive parameters cp[d][TTT_CP_*] (SI units, joint side) */
#define TTT_CP_RPC 0      /* joint angle of one encoder count (rad) */
#define TTT_CP_KP_POS 1   /* outer position PID: speed setpoint per rad (1/s), ... */
#define TTT_CP_KI_POS 2   /* ... per rad s (1/s^2) */
#define TTT_CP_KD_POS 3   /* ... per rad/s */
#define TTT_CP_KFF 4      /* speed feedforward from the setpoint filter's derivative */
#define TTT_CP_WMAX 5     /* speed setpoint clamp (rad/s) */
#define TTT_CP_KP_SPD 6   /* inner speed PID: duty per rad/s, ... */
#define TTT_CP_KI_SPD 7   /* ... per rad */
#define TTT_CP_KD_SPD 8   /* ... per rad/s^2 */
#define TTT_CP_ALPHA_W 9  /* speed filter: w += alpha * (w_raw - w) */
#define TTT_N_CP 10

/* global parameters cg[TTT_CG_*] */
#define TTT_CG_DT 0         /* control step (s) */
#define TTT_CG_SF_NORMAL 1  /* setpoint filter, normal: a11 a12 b1 a21 a22 b2 */
#define TTT_CG_SF_SLOW 7    /* setpoint filter, slow (fr_sw on): same layout */
#define TTT_CG_SV_MIN 13    /* servo: angle range (rad) ... */
#define TTT_CG_SV_MAX 14
#define TTT_CG_SV_PMIN 15   /* ... pulse widths at its ends and the PWM period (s) */
#define TTT_CG_SV_PMAX 16
#define TTT_CG_SV_PERIOD 17
#define TTT_N_CG 18

/* per-drive state cs[d][TTT_CS_*] */
#define TTT_CS_R_RAW 0      /* position setpoint as given (encoder coordinates, rad) */
#define TTT_CS_R_F 1        /* filtered setpoint (rad) */
#define TTT_CS_R_FD 2       /* its derivative (rad/s) */
#define TTT_CS_Q_PREV 3     /* previous measured angle (rad) */
#define TTT_CS_W_MEAS 4     /* filtered speed estimate (rad/s) */
#define TTT_CS_INT_POS 5    /* outer integrator (rad/s) */
#define TTT_CS_INT_SPD 6    /* inner integrator (duty) */
#define TTT_CS_W_REF 7      /* speed setpoint (rad/s) */
#define TTT_CS_DUTY_CMD 8   /* duty computed this step (applied next step) */
#define TTT_CS_OFFSET 9     /* encoder offset estimate (rad) */
#define TTT_CS_OPEN_DUTY 10 /* duty in open-loop mode */
#define TTT_N_CS 11

/* global state cgs[TTT_CGS_*] */
#define TTT_CGS_FR_SW 0       /* 1 while slow moves are selected */
#define TTT_CGS_SV_SET 1      /* servo angle setpoint (rad) */
#define TTT_CGS_SV_DUTY 2     /* its PWM duty (0..1) ... */
#define TTT_CGS_SV_DUTY_OF 3  /* ... computed for this setpoint (NaN: not yet) */
#define TTT_N_CGS 4

/* outputs act[TTT_ACT_*] */
#define TTT_ACT_DUTY 0     /* 3 values: duty applied to each H-bridge now (-1..1) */
#define TTT_ACT_BRIDGE 3   /* 3 values: 1 while the bridge is on, 0 while off */
#define TTT_ACT_SV_DUTY 6  /* servo PWM duty (0..1) */
#define TTT_N_ACT 7

/* modes cm[d] */
#define TTT_MODE_OFF 0     /* bridge off: the motor coasts */
#define TTT_MODE_CLOSED 1  /* cascade control */
#define TTT_MODE_OPEN 2    /* fixed duty; duty 0 shorts the motor (brakes) */

typedef struct ttt_cascade {
    ttt_real cp[TTT_DRIVES][TTT_N_CP];
    ttt_real cg[TTT_N_CG];
    ttt_real cs[TTT_DRIVES][TTT_N_CS];
    ttt_real cgs[TTT_N_CGS];
    ttt_real act[TTT_N_ACT];
    int32_t cm[TTT_DRIVES];
} ttt_cascade;

/* sizeof(ttt_real): 4 on a float build, 8 on a double build (for bindings). */
int ttt_real_size(void);

/* Zero everything, every drive closed, the servo's duty not yet computed.
 * The caller then writes cp and cg (the gains download) and the servo's
 * power-on setpoint. */
void ttt_cascade_init(ttt_cascade *c);

/* One control step: counts[d] (encoder counts since power-on) in, c->act out. */
void ttt_cascade_step(ttt_cascade *c, const int32_t counts[TTT_DRIVES]);

/* Setpoints: q[0..2] the drives (encoder coordinates, rad), q[3] the servo
 * angle (rad); fr_sw != 0 selects the slow setpoint filters. */
void ttt_cascade_set_setpoints(ttt_cascade *c, const ttt_real q[4], int fr_sw);

/* The encoder offset of drive d (rad): setpoints and speed-estimate state
 * move with it, so the arm does not jump. */
void ttt_cascade_set_offset(ttt_cascade *c, int d, ttt_real offset);

/* Hold the encoder angle q (rad) with no bump: filters and integrators reset. */
void ttt_cascade_hold(ttt_cascade *c, int d, ttt_real q);

/* Switch drive d to mode; entering closed loop holds hold_q (its angle now). */
void ttt_cascade_set_mode(ttt_cascade *c, int d, int32_t mode, ttt_real hold_q);

/* Open loop at a fixed duty (clipped to -1..1 by the step). */
void ttt_cascade_set_open_duty(ttt_cascade *c, int d, ttt_real duty);

/* The encoder angle of drive d for a count: count * rad_per_count + offset. */
ttt_real ttt_cascade_angle(const ttt_cascade *c, int d, int32_t count);

#endif

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
 * order.  The indices (TTT_CP_*, TTT_CG_*, TTT_CS_*, TTT_CGS_*, TTT_ACT_*,
 * TTT_MODE_*, TTT_N_*) are in layout.h, generated from the PC's tables
 * (src/ttt_sm/twin/layout.py); the struct ttt_cascade is in structs.h,
 * generated from src/ttt_sm/hardware/structs.py, whose table the PC's
 * ctypes binding is built from too.  No heap, no library call; the caller
 * owns the struct.
 *
 * Drives are indexed 0..2 here (drive 1 of the thesis is index 0).
 */
#ifndef TTT_FW_CASCADE_H
#define TTT_FW_CASCADE_H

#include <stdint.h>

#include "layout.h"
#include "real.h"
#include "structs.h" /* ttt_cascade and TTT_DRIVES, generated like layout.h */

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

/*
 * ttt_real: the one floating-point type of the firmware.
 *
 * float (IEEE 754 binary32) by default: the reference board (docs/hardware.md,
 * an STM32 Nucleo-F446RE, Cortex-M4F) has a single-precision FPU and no
 * double-precision one, where a double costs a software routine of tens of
 * cycles per operation.  binary32 resolves an angle of 3 rad to 2.4e-7 rad,
 * a hundredth of one encoder count (2e-5 rad), which is what the controller
 * needs (tests/hardware measure the duty difference to the PC's float64
 * step over a whole drawing).
 *
 * Build with -DTTT_FW_DOUBLE for a board with a double-precision FPU
 * (Cortex-M7 boards such as a Teensy 4.x) or for the PC: the step is then
 * the PC's float64 step operation for operation.
 *
 * Every literal goes through TTT_R() so that no expression is silently
 * promoted to double on a float build (-Wdouble-promotion checks it).
 * The firmware must be built without -ffast-math: the servo's "duty not yet
 * computed" marker is a NaN, and the anti-windup compares floats exactly.
 */
#ifndef TTT_FW_REAL_H
#define TTT_FW_REAL_H

#ifdef TTT_FW_DOUBLE
typedef double ttt_real;
#define TTT_R(x) (x)
#else
typedef float ttt_real;
#define TTT_R(x) (x##f)
#endif

#endif

"""The real arm's side of ``ttt_sm``: the firmware's C, built and loaded here, and the serial link to it.

The firmware (``firmware/`` in the source tree, portable C99, no heap) runs
each DC drive's cascade at the control rate on a microcontroller.  This
package compiles it with the system C compiler (:mod:`.firmware`) and
loads it with ctypes (:mod:`.native`), so the C that would be flashed is
the C the tests run.  docs/hardware.md describes the firmware, its number
type and the link.
"""

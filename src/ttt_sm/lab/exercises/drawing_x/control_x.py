"""Control with your Drawing_X (thesis section 3.6.1, eqs. 3.37-3.44).

The thesis' Control chart draws everything else; its Drawing_X sub-chart calls
the four methods below as it draws the X's two strokes.  Fill them in.
``ttt_sm.charts.geometry`` has the formulas as functions (x_line_1, on_x_line_1,
x_line_2, on_x_line_2), or write the equations yourself.
"""

from __future__ import annotations

from ttt_sm.charts import Control


class MyControl(Control):
    """The Control chart, with the strokes of the X written by you."""

    def during_line_1(self) -> None:
        # TODO eqs. 3.40-3.41: X_out decreases by speed * tick_period_s / sqrt(2) per tick (not below
        # x_ini - size); Y_out follows the 45-degree line Y = X + h1
        pass

    def end_line_1(self) -> None:
        # TODO: remember where line 1 ended (Y_end), then lift the pen (self.aim_up())
        self.aim_up()

    def aim_line_2(self) -> None:
        # TODO eq. 3.42: h2 = Y_end + x_ini; travel to (x_ini, Y_end) at z_up: self._aim(x, y, z)
        self._aim(self.x_ini, self.y_ini, self.z_up)

    def during_line_2(self) -> None:
        # TODO eqs. 3.43-3.44: as line 1, along Y = -X + h2
        pass

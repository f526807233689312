"""The Control chart's ``Erase`` and ``finishing`` sub-charts (thesis section 3.6.1, fig. 3.24).

``Erase``: phi to 90 degrees, the sponge down, passes along Y 3 cm apart over the field, the field flag and
the symbol counter reset, phi back to 0.  ``finishing``: the pen lifted from wherever it is, the arm back to
its start pose.  Mixed into :class:`~.control.Control`, whose data these actions read and write.
"""

from __future__ import annotations

from ..runtime import ChartActions, does
from .geometry import pass_ends, pass_x


class Erasing(ChartActions):
    """``Erase``: the sponge's passes over the field."""

    tick_period_s: float
    phi: float

    def on_enter_Erase(self) -> None:
        self.erasing = True
        self._aim(self.X_out, self.Y_out, max(self.Z_out, self.z_travel))

    def on_exit_Erase(self) -> None:
        self.erasing = False

    def during_erase_lift(self) -> None:
        self._move(self.z_speed * 2)

    @does("phi = min(phi + phi_rate*dt, pi/2)")
    def during_turn_sponge(self) -> None:
        self.phi = min(self.phi + self.phi_rate * self.tick_period_s, self.pi_2)

    def _pass_x(self, k: int) -> float:
        return pass_x(self.x11, self.L, self.cells, k)

    def _pass_ends(self, k: int) -> tuple[float, float]:
        """Passes along Y over the whole field (and 5 mm beyond), alternately one way and back."""
        return pass_ends(self.y11, self.L, self.cells, k)

    @does("k = 0; aim(pass_x(0), pass_start(0), z_travel)")
    def aim_pass_start(self) -> None:
        self.k = 0
        self._aim(self._pass_x(0), self._pass_ends(0)[0], self.z_travel)

    def during_to_pass(self) -> None:
        self._move(self.travel_speed)

    def aim_sponge_down(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_sponge)

    def during_sponge_down(self) -> None:
        self._move(self.z_speed)

    @does("aim(X_out, pass_end(k), z_sponge)")
    def aim_pass_end(self) -> None:
        self._aim(self.X_out, self._pass_ends(self.k)[1], self.z_sponge)

    def during_wipe(self) -> None:
        self._move(self.wipe_speed)

    def aim_sponge_up(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_sponge + 0.01)

    def during_sponge_up(self) -> None:
        self._move(self.z_speed)

    @does("k = k + 1; aim(pass_x(k), pass_start(k), z_sponge + 0.01)")
    def next_pass(self) -> None:
        self.k = self.k + 1
        self._aim(self._pass_x(self.k), self._pass_ends(self.k)[0], self.z_sponge + 0.01)

    def erased(self) -> None:
        self.Pl_fld = False
        self.ctr = 0
        self._aim(self.X_out, self.Y_out, self.z_travel)

    def during_turn_pen(self) -> None:
        self._move(self.z_speed * 2)
        self.phi = max(self.phi - self.phi_rate * self.tick_period_s, 0.0)


class Finishing(ChartActions):
    """``finishing``: back to the start pose."""

    tick_period_s: float
    phi: float

    def during_finishing(self) -> None:
        self.fr_sw = False
        self.phi = max(self.phi - self.phi_rate * self.tick_period_s, 0.0)

    def during_home_lift(self) -> None:
        self._move(self.z_speed * 2)

    def aim_home_over(self) -> None:
        self._aim(self.x_start, self.y_start, self.Z_out)

    def during_go_home_over(self) -> None:
        self._move(self.travel_speed)

    def aim_home(self) -> None:
        self._aim(self.x_start, self.y_start, self.z_start)

    def during_go_home(self) -> None:
        self._move(self.z_speed * 2)

    def on_enter_finished(self) -> None:
        self.at_start = True

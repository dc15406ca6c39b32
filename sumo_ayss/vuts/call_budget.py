"""The per-call time budget of a VUT (Python controller, FMU or process): measure, warn, stop.

Every call of a VUT's ``acceleration(state)`` is timed (wall clock, :func:`time.perf_counter`).

* **Deadline.** A call that takes longer than the VUT's ``call_deadline_s`` (default
  :data:`~sumo_ayss.vuts.controller_spec.DEFAULT_CALL_DEADLINE_S`) stops the run with a
  :class:`~sumo_ayss.util.errors.ControllerError` naming the VUT, the call's time and the
  deadline. An in-process call (a Python controller, an FMU) cannot be interrupted: it is
  judged when it returns. An external process is not waited for past the deadline
  (:mod:`sumo_ayss.vuts.process`).
* **Share of the step.** Over windows of at least :data:`WINDOW_S` seconds (and
  :data:`WINDOW_CALLS` calls) the VUT's share of the wall time since the window began (its
  calls, SUMO's step, the POV, the learner) is computed; a window that short holds the odd
  long call (a preempted process on a busy machine, a garbage collection) among many; the
  first window in which the VUT takes more than :data:`WARN_SHARE` of it logs one warning
  with its mean and largest call time: once per VUT and Python process (the pairs of a
  vectorised env each time their own calls, and would otherwise warn once each).
"""

from __future__ import annotations

import logging
import time

from sumo_ayss.util.errors import ControllerError

__all__ = ["WARN_SHARE", "WINDOW_CALLS", "WINDOW_S", "CallBudget"]

logger = logging.getLogger(__name__)

#: The VUT's share of the wall time above which it "dominates the step" (one warning).
WARN_SHARE = 0.5
#: Least calls per measurement window of that share.
WINDOW_CALLS = 50
#: Least wall time of a measurement window [s].
WINDOW_S = 2.0

#: The VUTs (by label) warned about in this Python process.
_WARNED: set[str] = set()


class CallBudget:
    """Times a VUT's calls against a deadline and warns once when they dominate.

    Args:
        label: How messages name the VUT (``"FMU 'acc.fmu'"``).
        deadline_s: Longest wall time one call may take [s], > 0.
        window_s: Least wall time of a share window [s].

    Attributes:
        calls: Calls timed so far.
        total_s: Their summed wall time [s].
        max_s: The longest one [s].
        warned: Whether the share warning was logged.
    """

    def __init__(self, label: str, deadline_s: float, window_s: float = WINDOW_S) -> None:
        self.label = label
        self.deadline_s = float(deadline_s)
        self.window_s = float(window_s)
        self.calls = 0
        self.total_s = 0.0
        self.max_s = 0.0
        self.warned = False
        self._window_start: float | None = None
        self._window_calls = 0
        self._window_s = 0.0

    @property
    def mean_s(self) -> float:
        """Mean wall time per call [s] (0 before the first)."""
        return self.total_s / self.calls if self.calls else 0.0

    def record(self, start_s: float, elapsed_s: float) -> None:
        """Account one call that began at ``start_s`` (perf_counter) and took ``elapsed_s``.

        Raises:
            ControllerError: The call took longer than the deadline.
        """
        self.calls += 1
        self.total_s += elapsed_s
        self.max_s = max(self.max_s, elapsed_s)
        if elapsed_s > self.deadline_s:
            raise ControllerError(
                f"{self.label}: one call took {elapsed_s:.3g} s, past its deadline "
                f"call_deadline_s = {self.deadline_s:g} s ({self.calls} calls, mean "
                f"{self.mean_s * 1e3:.3g} ms); raise call_deadline_s in the VUT's config if "
                "this is expected"
            )
        if self.warned:
            return
        if self._window_start is None:
            self._window_start = start_s
        self._window_calls += 1
        self._window_s += elapsed_s
        wall_s = time.perf_counter() - self._window_start
        if self._window_calls < WINDOW_CALLS or wall_s < self.window_s:
            return
        share = self._window_s / wall_s if wall_s > 0 else 0.0
        if share > WARN_SHARE:
            self.warned = True
            if self.label in _WARNED:
                return
            _WARNED.add(self.label)
            logger.warning(
                "%s takes %.3g ms per call (largest %.3g ms): %.0f %% of the wall time of its "
                "last %d steps; the run's speed is the VUT's",
                self.label,
                self._window_s / self._window_calls * 1e3,
                self.max_s * 1e3,
                100 * share,
                self._window_calls,
            )
        self._window_start, self._window_calls, self._window_s = None, 0, 0.0

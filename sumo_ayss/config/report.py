"""The report's section, ``report`` of a pipeline YAML: statistical settings and analysis
modes of a report and a ranking (:class:`ReportOptions`). A configuration section like the
others (no heavy imports); the report and the leaderboard read it from here."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar, Literal

from sumo_ayss.validation import check_choice, check_int, check_number, require

if TYPE_CHECKING:
    import numpy as np

__all__ = ["CROSSPLAY_BLOCKS", "DEFAULT_MODE", "MODES", "ReportOptions"]


# --------------------------------------------------------------------------- options

MODES: Mapping[str, str] = {
    "crossplay": (
        "Cross-play mode (default): every SPCP of a case drives against every VUT of the case "
        "on the same outcome scenarios; a VUT's score H is the mean harm per episode this "
        "pooled population of opponents brings about against it (1 for a collision, else the "
        "near-miss reward paid over the most an episode can pay), and a lower H is a safer "
        "VUT. A collision is the worst outcome for the VUT, never its gain. A difference "
        "between two VUTs is read within each opponent, so the search noise of one SPCP "
        "cancels; two VUTs are compared by a paired t-test over training-seed blocks (block s "
        "= the mean over seed s's opponents; report.crossplay_blocks: opponent makes every "
        "opponent a block); significant when p < alpha. Crash rate and mobility (mean VUT "
        "speed) stand beside the score; a VUT far slower than the others is flagged TIMID."
    ),
    "exposure": (
        "Exposure mode: a VUT's score is the mean harm per episode its own SPCPs bring about "
        "over the common outcome scenarios (the same scenarios for every VUT and seed; harm as "
        "in cross-play mode); a lower score is a safer VUT. Each training seed's SPCP is one "
        "observation; seeds are shared across VUTs (same seed values), so "
        "two VUTs are compared by a paired t-test on their per-seed differences (Welch's "
        "t-test when the seed sets differ); significant when p < alpha."
    ),
    "paper": (
        "Paper mode: the paper's indicator, the aggressiveness of the SPCP's action in the "
        "adversarial-yet-safe states (POV acceleration in car-following, Δv̄ in cut-in), "
        "condensed into a safety index over headway bins; meaningful only when the SPCPs "
        "reached the same overall outcome (the premise check)."
    ),
}
"""The analysis modes of a report, with their description."""

DEFAULT_MODE = "crossplay"
"""The mode of a report and a ranking unless ``report.mode`` says otherwise."""

CROSSPLAY_BLOCKS = ("seed", "opponent")
"""Block units of cross-play's paired test (:data:`sumo_ayss.analysis.crossplay.BLOCKS`)."""


@dataclass(frozen=True)
class ReportOptions:
    """Statistical settings of a report.

    Attributes:
        h_max_m: AYSS headway range is ``[0, h_max_m]`` m (the paper keeps h <= 5 m).
        bin_width_m: Headway bin width of the indicator-vs-headway figure, m.
        index_bins: Equal-width headway bins of the safety index over ``[0, h_max_m]``.
        level: Confidence level of every interval.
        n_boot: Bootstrap replicates per safety index (the same for every VUT).
        welch_alpha: The seed-level Welch p-value must be below this for significance.
        rng_seed: Root seed of the bootstraps; each (case, VUT) gets its own stream.
        mode: Which analysis gives the verdicts and the ranking (see :data:`MODES`):
            ``"crossplay"`` (default), ``"exposure"`` or ``"paper"``. Every mode available
            is computed and shown; cross-play needs the case's ``crossplay.csv``.
        crossplay_blocks: Block unit of cross-play's paired test: ``"seed"`` (default,
            training seeds) or ``"opponent"`` (every opponent SPCP its own block).
        premise_reward: Tolerance on the spread of the VUTs' mean episode reward for the
            premise check ("same overall outcome"), reward per episode.
        premise_crash_rate: Tolerance on the spread of crash rates, fraction.
        premise_final_headway_m: Tolerance on the spread of mean final headways, m.
    """

    SECTION: ClassVar[str] = "report"

    h_max_m: float = 5.0
    bin_width_m: float = 0.25
    index_bins: int = 10
    level: float = 0.95
    n_boot: int = 2000
    welch_alpha: float = 0.05
    rng_seed: int = 0
    mode: Literal["crossplay", "exposure", "paper"] = "crossplay"
    crossplay_blocks: Literal["seed", "opponent"] = "seed"
    premise_reward: float = 1.0
    premise_crash_rate: float = 0.02
    premise_final_headway_m: float = 2.0

    def __post_init__(self) -> None:
        s = self.SECTION
        check_choice(f"{s}.mode", self.mode, list(MODES))
        check_choice(f"{s}.crossplay_blocks", self.crossplay_blocks, list(CROSSPLAY_BLOCKS))
        for name in ("premise_reward", "premise_crash_rate", "premise_final_headway_m"):
            value = getattr(self, name)
            require(
                isinstance(value, int | float) and math.isfinite(value) and value >= 0,
                f"{s}.{name} must be a finite number >= 0, got {value!r}",
            )
        check_number(f"{s}.h_max_m", self.h_max_m, low=0.0, low_open=True)
        require(
            0 < self.bin_width_m <= self.h_max_m,
            f"{s}.bin_width_m must be in (0, h_max_m = {self.h_max_m}], got {self.bin_width_m}",
        )
        check_int(f"{s}.index_bins", self.index_bins, low=1)
        check_int(f"{s}.n_boot", self.n_boot, low=1)
        check_int(f"{s}.rng_seed", self.rng_seed, low=0)
        for name in ("level", "welch_alpha"):
            value = getattr(self, name)
            require(0 < value < 1, f"{s}.{name} must be in (0, 1), got {value!r}")

    @property
    def premise_tolerances(self) -> dict[str, float]:
        """Tolerances of the premise check by metric key."""
        return {
            "mean_return": self.premise_reward,
            "crash_rate": self.premise_crash_rate,
            "mean_final_headway_m": self.premise_final_headway_m,
        }

    @property
    def h_range(self) -> tuple[float, float]:
        """``(0, h_max_m)``."""
        return (0.0, self.h_max_m)

    @property
    def figure_edges(self) -> np.ndarray:
        """Headway bin edges of the indicator figure, m."""
        import numpy as np  # lazily: configuration loads this module

        n = max(1, round(self.h_max_m / self.bin_width_m))
        return np.linspace(0.0, self.h_max_m, n + 1)

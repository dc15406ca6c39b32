"""VUT catalog: the paper's VUTs, validation before SUMO starts, and routes/ in sync."""

from __future__ import annotations

import pytest

from sumo_ayss.config import PROJECT_ROOT
from sumo_ayss.sim.network import write_vtypes_file
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.catalog import BUILTIN_VUTS, MODEL_PARAMS, POV_TYPE, VehicleType, vtypes_xml


def test_paper_vuts() -> None:
    for name, min_gap in (("pi1", 5.0), ("pi2", 15.0)):
        p = BUILTIN_VUTS[name].params
        assert BUILTIN_VUTS[name].model == "IDM"
        assert p["minGap"] == min_gap
        assert (p["accel"], p["decel"], p["emergencyDecel"], p["tau"], p["delta"]) == (
            3.0,
            5.0,
            6.0,
            1.5,
            4.0,
        )
        assert p["length"] == 5.0 and p["speedDev"] == 0.0


def test_routes_file_matches_catalog(tmp_path) -> None:
    """routes/vtypes.add.xml is generated from the catalog: it must not drift."""
    types = {f"vut_{k}": v for k, v in BUILTIN_VUTS.items()} | {"pov": POV_TYPE}
    expected = vtypes_xml(types)
    assert (PROJECT_ROOT / "routes" / "vtypes.add.xml").read_text() == expected
    assert write_vtypes_file(tmp_path / "v.add.xml").read_text() == expected


@pytest.mark.parametrize("model", sorted(MODEL_PARAMS))
def test_every_model_accepts_its_own_parameters(model: str) -> None:
    VehicleType(model, {p: 1.0 for p in MODEL_PARAMS[model]}).validate("vut")


def test_errors() -> None:
    with pytest.raises(ConfigError, match=r"vut\.model must be one of .* got 'Kraus'.*'Krauss'"):
        VehicleType("Kraus").validate("vut")
    with pytest.raises(ConfigError, match=r"vut\.params\.delta is not a parameter of .*Krauss"):
        VehicleType("Krauss", {"delta": 4}).validate("vut")
    with pytest.raises(ConfigError, match=r"vut\.params\.tau must be > 0"):
        VehicleType("IDM", {"tau": 0}).validate("vut")
    with pytest.raises(ConfigError, match=r"emergencyDecel must be >= decel"):
        VehicleType("IDM", {"decel": 5, "emergencyDecel": 4}).validate("vut")
    with pytest.raises(ConfigError, match=r"vut\.params\.accel must be a number"):
        VehicleType("IDM", {"accel": "fast"}).validate("vut")

"""Networks rebuild with the pip-installed netconvert and have the documented geometry."""

from __future__ import annotations

from pathlib import Path

import pytest
import sumolib

from sumo_ayss.sim.network import (
    LANE_WIDTH_M,
    NETWORK_DIR,
    ROAD_EDGE,
    ROAD_LENGTH_M,
    SPEED_LIMIT_MPS,
    build_network,
)


@pytest.mark.parametrize(("stem", "lanes"), [("straight_1lane", 1), ("straight_2lane", 2)])
def test_rebuild_and_check_geometry(tmp_path: Path, stem: str, lanes: int) -> None:
    built = build_network(stem, out_dir=tmp_path)
    for path in (built, NETWORK_DIR / f"{stem}.net.xml"):  # fresh build and committed file
        net = sumolib.net.readNet(str(path))
        edge = net.getEdge(ROAD_EDGE)
        assert edge.getLaneNumber() == lanes
        for lane in edge.getLanes():
            assert lane.getLength() == pytest.approx(ROAD_LENGTH_M)
            assert lane.getSpeed() == pytest.approx(SPEED_LIMIT_MPS)
            assert lane.getWidth() == pytest.approx(LANE_WIDTH_M)
    # 40 m/s for a 5 s episode from the start zone (<= 150 + 25 + 5 m) stays on the road.
    assert ROAD_LENGTH_M - 50 > 150 + 25 + 5 + 40 * 5

"""The built-in SUMO world: networks rebuilt with the pip-installed ``netconvert``.

Run ``python -m sumo_ayss.sim.network`` (or ``make networks``) to rebuild every
``networks/*.net.xml`` from its plain-XML sources (``.nod.xml``, ``.edg.xml``) and to
rewrite ``routes/vtypes.add.xml`` (the POV and the built-in VUTs) from the catalog.
"""

from __future__ import annotations

import argparse
import os
import subprocess
from pathlib import Path

from sumo_ayss.cases import ROAD_EDGE as ROAD_EDGE  # the only edge of every built-in network
from sumo_ayss.cases import get_case, registered_cases
from sumo_ayss.config import PROJECT_ROOT, Case
from sumo_ayss.util.errors import SimulationError
from sumo_ayss.vuts.catalog import BUILTIN_VUTS, POV_TYPE, vtypes_xml

NETWORK_DIR = PROJECT_ROOT / "networks"

ROAD_LENGTH_M = 1000.0
SPEED_LIMIT_MPS = 30.0
LANE_WIDTH_M = 3.2


def sumo_home() -> Path:
    """SUMO_HOME of the pip package ``eclipse-sumo`` (no system SUMO is needed)."""
    import sumo  # the eclipse-sumo wheel; imported lazily so that import is cheap

    return Path(sumo.SUMO_HOME)


def sumo_binary(name: str) -> Path:
    """Path of a SUMO tool (``sumo``, ``netconvert``, ``sumo-gui``) from the pip package."""
    path = sumo_home() / "bin" / name
    if not path.exists():
        raise SimulationError(f"SUMO tool {name!r} not found at {path}; reinstall eclipse-sumo")
    return path


def network_path(case: Case) -> Path:
    """The built ``.net.xml`` of a case's built-in network (:attr:`Case.network
    <sumo_ayss.cases.Case.network>`)."""
    return NETWORK_DIR / f"{get_case(case).network}.net.xml"


def build_network(stem: str, directory: Path = NETWORK_DIR, out_dir: Path | None = None) -> Path:
    """Build ``<stem>.net.xml`` from ``<stem>.nod.xml`` and ``<stem>.edg.xml``."""
    out = (out_dir or directory) / f"{stem}.net.xml"
    cmd = [
        str(sumo_binary("netconvert")),
        "--node-files", f"{stem}.nod.xml",
        "--edge-files", f"{stem}.edg.xml",
        "--output-file", os.path.relpath(out.resolve(), directory),
        "--no-turnarounds", "true",
        "--no-internal-links", "true",
        "--offset.disable-normalization", "true",
        "--output.street-names", "false",
        "--xml-validation", "never",
        "--no-warnings", "true",
        "--write-license", "false",
    ]  # fmt: skip
    # Run in the sources' folder so the file's header records relative input paths.
    result = subprocess.run(cmd, capture_output=True, text=True, check=False, cwd=directory)
    if result.returncode != 0:
        raise SimulationError(f"netconvert failed for {stem}: {result.stderr.strip()}")
    return out


#: Lateral distance between neighbouring roads of a parallel network [m]. SUMO's vehicles
#: perceive and collide only along lanes of their own edge; the spacing keeps the drawn
#: bodies apart too (a 2-lane road is 6.4 m wide), e.g. in sumo-gui.
PARALLEL_ROAD_SPACING_M = 50.0


def parallel_road_edge(index: int) -> str:
    """Edge id of road ``index`` of a parallel network (lanes ``road<index>_<lane>``)."""
    return f"road{index}"


def parallel_road_y_m(index: int) -> float:
    """World y [m] of road ``index``'s reference line (road 0 lies where the built-in road does)."""
    return 0.0 - PARALLEL_ROAD_SPACING_M * index  # 0.0 - ...: no -0.0 for road 0


def build_parallel_network(n_roads: int, lanes: int, out_dir: Path) -> Path:
    """Build ``n_roads`` parallel copies of the built-in straight road into ``out_dir``.

    Road ``i`` is edge :func:`parallel_road_edge` ``(i)`` from node ``s<i>`` at ``(0, y_i)`` to
    ``e<i>`` at ``(ROAD_LENGTH_M, y_i)``, with ``y_i =`` :func:`parallel_road_y_m` ``(i)``: every
    road has the built-in road's length (1000 m), lane count, lane width (3.2 m) and speed
    limit (30 m/s), and road 0 has exactly its geometry. The roads share no node, so a vehicle
    on one can never reach, perceive or touch a vehicle on another. Writes ``parallel_<n>x<lanes>
    .nod.xml``/``.edg.xml`` and builds the ``.net.xml`` with the pip-installed netconvert.

    Args:
        n_roads: number of roads, >= 1.
        lanes: lanes per road (1 for car-following, 2 for cut-in), >= 1.
        out_dir: existing folder for the plain-XML sources and the network.

    Returns:
        Path of the built ``.net.xml``.
    """
    if n_roads < 1 or lanes < 1:
        raise SimulationError(f"a parallel network needs >= 1 road and lane, got {n_roads}x{lanes}")
    stem = f"parallel_{n_roads}x{lanes}"
    nodes = [
        f'    <node id="s{i}" x="0.0" y="{parallel_road_y_m(i)!r}" type="priority"/>\n'
        f'    <node id="e{i}" x="{ROAD_LENGTH_M!r}" y="{parallel_road_y_m(i)!r}" type="priority"/>'
        for i in range(n_roads)
    ]
    edges = [
        f'    <edge id="{parallel_road_edge(i)}" from="s{i}" to="e{i}" numLanes="{lanes}" '
        f'speed="{SPEED_LIMIT_MPS!r}" width="{LANE_WIDTH_M!r}" priority="1"/>'
        for i in range(n_roads)
    ]
    head = '<?xml version="1.0" encoding="UTF-8"?>\n'
    (out_dir / f"{stem}.nod.xml").write_text(head + "<nodes>\n" + "\n".join(nodes) + "\n</nodes>\n")
    (out_dir / f"{stem}.edg.xml").write_text(head + "<edges>\n" + "\n".join(edges) + "\n</edges>\n")
    return build_network(stem, directory=out_dir)


def main(argv: list[str] | None = None) -> None:
    from sumo_ayss.cli import prog

    parser = argparse.ArgumentParser(
        prog=prog("python -m sumo_ayss.sim.network"), description=__doc__.splitlines()[0]
    )
    parser.add_argument("--out-dir", type=Path, default=None, help="default: networks/")
    args = parser.parse_args(argv)
    for stem in sorted({case.network for case in registered_cases() if case.network}):
        print(build_network(stem, out_dir=args.out_dir))
    print(write_vtypes_file((args.out_dir or PROJECT_ROOT / "routes") / "vtypes.add.xml"))


def write_vtypes_file(path: Path) -> Path:
    """The catalog's POV and built-in VUTs as a SUMO additional file (ids ``vut_<name>``)."""
    types = {f"vut_{name}": vt for name, vt in BUILTIN_VUTS.items()} | {"pov": POV_TYPE}
    path.write_text(vtypes_xml(types))
    return path


if __name__ == "__main__":
    main()

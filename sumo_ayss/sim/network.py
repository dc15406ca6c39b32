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

from sumo_ayss.catalog import BUILTIN_VUTS, POV_TYPE, vtypes_xml
from sumo_ayss.config import PROJECT_ROOT, Case
from sumo_ayss.errors import SimulationError

NETWORK_DIR = PROJECT_ROOT / "networks"

#: Built-in network stem per case: one lane for car-following, two for cut-in.
NETWORK_OF_CASE: dict[Case, str] = {
    "car_following": "straight_1lane",
    "cut_in": "straight_2lane",
}

#: The only edge of every built-in network; lane ``road_0`` is the rightmost.
ROAD_EDGE = "road"
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
    """The built ``.net.xml`` of a case's built-in network."""
    return NETWORK_DIR / f"{NETWORK_OF_CASE[case]}.net.xml"


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


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=None, help="default: networks/")
    args = parser.parse_args(argv)
    for stem in sorted(set(NETWORK_OF_CASE.values())):
        print(build_network(stem, out_dir=args.out_dir))
    print(write_vtypes_file((args.out_dir or PROJECT_ROOT / "routes") / "vtypes.add.xml"))


def write_vtypes_file(path: Path) -> Path:
    """The catalog's POV and built-in VUTs as a SUMO additional file (ids ``vut_<name>``)."""
    types = {f"vut_{name}": vt for name, vt in BUILTIN_VUTS.items()} | {"pov": POV_TYPE}
    path.write_text(vtypes_xml(types))
    return path


if __name__ == "__main__":
    main()

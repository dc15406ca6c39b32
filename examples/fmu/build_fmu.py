"""Build the time-gap ACC FMU (FMI 2.0 or 3.0 co-simulation) from its C source, here.

The law is :class:`examples.acc_controller.TimeGapACC`'s, written in C (``acc_law.h``) behind
the FMI 2.0 (``acc_fmi2.c``) or FMI 3.0 (``acc_fmi3.c``) interface, compiled with this
machine's C compiler against the FMI headers that fmpy ships (``fmpy/c-code``). The C files
implement the functions the testbed calls; every other function of the standard is added as
a stub that returns ``fmiError`` (generated from fmpy's list, so that fmpy can load the
library).

Usage (from the repository root)::

    python -m examples.fmu.build_fmu --fmi 2 runs/fmus/acc.fmu     # C, FMI 2.0
    python -m examples.fmu.build_fmu --fmi 3 runs/fmus/acc3.fmu    # C, FMI 3.0
    python -m examples.fmu.build_fmu --python runs/fmus/           # acc_slave.py, pythonfmu

The FMU's variables (all SI units)::

    inputs      v_ego [m/s], gap [m] (+inf: no leader), v_rel [m/s], has_lead (Boolean)
    outputs     a_cmd [m/s^2], v_cmd [m/s] (v_ego + a_cmd * dt)
    parameters  time_gap_s, standstill_gap_m, gap_gain, rel_speed_gain, set_speed_mps,
                cruise_gain, max_accel_mps2, max_decel_mps2 (TimeGapACC's defaults)
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = "TimeGapAcc"
INPUTS = (("v_ego", 0, "Real"), ("gap", 1, "Real"), ("v_rel", 2, "Real"), ("has_lead", 3, "Bool"))
OUTPUTS = (("a_cmd", 4), ("v_cmd", 5))
PARAMETERS = (
    ("time_gap_s", 10, 1.5),
    ("standstill_gap_m", 11, 5.0),
    ("gap_gain", 12, 0.3),
    ("rel_speed_gain", 13, 0.8),
    ("set_speed_mps", 14, 30.0),
    ("cruise_gain", 15, 0.4),
    ("max_accel_mps2", 16, 3.0),
    ("max_decel_mps2", 17, 6.0),
)


def compiler() -> str | None:
    """The C compiler found on ``PATH`` (``cc``, ``gcc`` or ``clang``), or ``None``."""
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return found
    return None


def model_description(fmi_version: int, interface: str = "CoSimulation") -> str:
    """The ``modelDescription.xml`` of the ACC FMU (``interface``: ``CoSimulation`` or
    ``ModelExchange``; ``fmi_version`` 1 writes a minimal FMI 1.0 description)."""
    token = "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, f"sumo_ayss/{MODEL}/{fmi_version}")) + "}"
    if fmi_version == 1:
        return (
            '<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="1.0" modelName="{MODEL}" '
            f'modelIdentifier="{MODEL}" guid="{token}" numberOfContinuousStates="0" '
            'numberOfEventIndicators="0">\n  <ModelVariables/>\n</fmiModelDescription>\n'
        )
    lines = ['<?xml version="1.0" encoding="UTF-8"?>']
    if fmi_version == 2:
        lines.append(
            f'<fmiModelDescription fmiVersion="2.0" modelName="{MODEL}" guid="{token}" '
            'variableNamingConvention="flat">'
        )
    else:
        lines.append(
            f'<fmiModelDescription fmiVersion="3.0" modelName="{MODEL}" '
            f'instantiationToken="{token}">'
        )
    extra = ' canHandleVariableCommunicationStepSize="true"' if interface == "CoSimulation" else ""
    lines += [f'  <{interface} modelIdentifier="{MODEL}"{extra}/>', "  <ModelVariables>"]
    if fmi_version == 2:
        for name, vr, kind in INPUTS:
            tag = '<Real start="0"/>' if kind == "Real" else '<Boolean start="false"/>'
            var = "continuous" if kind == "Real" else "discrete"
            lines.append(
                f'    <ScalarVariable name="{name}" valueReference="{vr}" causality="input" '
                f'variability="{var}">{tag}</ScalarVariable>'
            )
        for name, vr in OUTPUTS:
            lines.append(
                f'    <ScalarVariable name="{name}" valueReference="{vr}" causality="output" '
                'variability="continuous" initial="calculated"><Real/></ScalarVariable>'
            )
        for name, vr, start in PARAMETERS:
            lines.append(
                f'    <ScalarVariable name="{name}" valueReference="{vr}" causality="parameter" '
                f'variability="fixed" initial="exact"><Real start="{start}"/></ScalarVariable>'
            )
        outs = [len(INPUTS) + i + 1 for i in range(len(OUTPUTS))]  # 1-based indices
        lines += [
            "  </ModelVariables>",
            "  <ModelStructure>",
            "    <Outputs>" + "".join(f'<Unknown index="{i}"/>' for i in outs) + "</Outputs>",
            "    <InitialUnknowns>"
            + "".join(f'<Unknown index="{i}"/>' for i in outs)
            + "</InitialUnknowns>",
            "  </ModelStructure>",
        ]
    else:
        lines.append(
            '    <Float64 name="time" valueReference="100" causality="independent" '
            'variability="continuous"/>'
        )
        for name, vr, kind in INPUTS:
            tag = "Float64" if kind == "Real" else "Boolean"
            start = "0" if kind == "Real" else "false"
            lines.append(
                f'    <{tag} name="{name}" valueReference="{vr}" causality="input" '
                f'start="{start}"/>'
            )
        for name, vr in OUTPUTS:
            lines.append(f'    <Float64 name="{name}" valueReference="{vr}" causality="output"/>')
        for name, vr, start in PARAMETERS:
            lines.append(
                f'    <Float64 name="{name}" valueReference="{vr}" causality="parameter" '
                f'variability="fixed" start="{start}"/>'
            )
        lines += [
            "  </ModelVariables>",
            "  <ModelStructure>",
            *(f'    <Output valueReference="{vr}"/>' for _, vr in OUTPUTS),
            *(f'    <InitialUnknown valueReference="{vr}"/>' for _, vr in OUTPUTS),
            "  </ModelStructure>",
        ]
    lines.append("</fmiModelDescription>")
    return "\n".join(lines) + "\n"


def _stubs(fmi_version: int, source: str) -> str:
    """C stubs returning ``fmiError`` (3) for every FMI function fmpy loads that ``source``
    does not define (their arguments are ignored; only the status is returned)."""
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    prefix = f"fmi{fmi_version}"
    cls = FMU2Slave if fmi_version == 2 else FMU3Slave
    defined = set(re.findall(rf"\b({prefix}\w+)\s*\(", source))
    wanted = sorted(n for n in dir(cls) if n.startswith(prefix) and n not in defined)
    body = "/* Generated by build_fmu.py: functions the ACC does not implement. */\n"
    return body + "".join(f"int {name}(void) {{ return 3; }}\n" for name in wanted)


def build_acc_fmu(
    dest: Path,
    fmi_version: int = 2,
    *,
    interface: str = "CoSimulation",
    binary: bool = True,
    cc: str | None = None,
) -> Path:
    """Compile and zip the ACC FMU to ``dest`` (a ``.fmu`` path); returns ``dest``.

    Args:
        dest: The FMU file to write (its folder is created).
        fmi_version: 2 or 3 (1 writes an FMI 1.0 description without a binary, for tests
            of the error a wrong version gives).
        interface: ``CoSimulation`` or ``ModelExchange`` (the latter without a binary).
        binary: Compile the platform binary (``False``: an FMU without one).
        cc: The C compiler (default: :func:`compiler`).

    Raises:
        RuntimeError: No C compiler, or the compiler failed (its output in the message).
    """
    import fmpy

    dest = Path(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="acc_fmu_") as tmp:
        root = Path(tmp)
        (root / "modelDescription.xml").write_text(model_description(fmi_version, interface))
        if binary and interface == "CoSimulation" and fmi_version in (2, 3):
            cc = cc or compiler()
            if cc is None:
                raise RuntimeError("no C compiler (cc, gcc or clang) on PATH")
            source = HERE / f"acc_fmi{fmi_version}.c"
            stubs = root / "stubs.c"
            stubs.write_text(_stubs(fmi_version, source.read_text()))
            folder = fmpy.platform if fmi_version == 2 else fmpy.platform_tuple
            out = root / "binaries" / folder / f"{MODEL}{fmpy.sharedLibraryExtension}"
            out.parent.mkdir(parents=True)
            headers = Path(fmpy.__file__).parent / "c-code"
            cmd = [cc, "-shared", "-fPIC", "-O2", "-ffp-contract=off", f"-I{headers}",
                   f"-I{HERE}", str(source), str(stubs), "-o", str(out)]  # fmt: skip
            done = subprocess.run(cmd, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")
            stubs.unlink()
        with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zf:
            for path in sorted(root.rglob("*")):
                if path.is_file():
                    zf.write(path, path.relative_to(root).as_posix())
    return dest


def build_python_fmu(script: Path, dest_dir: Path) -> Path:
    """Export the pythonfmu slave in ``script`` as an FMU into ``dest_dir``; its path.

    Runs ``python -m pythonfmu build`` in the script's folder (it imports the script).

    Raises:
        RuntimeError: pythonfmu failed (its output in the message).
    """
    script = Path(script).resolve()
    dest_dir = Path(dest_dir).resolve()
    dest_dir.mkdir(parents=True, exist_ok=True)
    before = set(dest_dir.glob("*.fmu"))
    cmd = [sys.executable, "-m", "pythonfmu", "build", "-f", script.name, "-d", str(dest_dir)]
    done = subprocess.run(cmd, cwd=script.parent, capture_output=True, text=True, check=False)
    built = sorted(set(dest_dir.glob("*.fmu")) - before) or sorted(dest_dir.glob("*.fmu"))
    if done.returncode != 0 or not built:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")
    return built[-1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dest", type=Path, help="the .fmu file to write (--python: a folder)")
    parser.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version")
    parser.add_argument(
        "--python", action="store_true", help="export acc_slave.py with pythonfmu instead"
    )
    args = parser.parse_args()
    if args.python:
        print(build_python_fmu(HERE / "acc_slave.py", args.dest))
    else:
        print(build_acc_fmu(args.dest, args.fmi))


if __name__ == "__main__":
    main()

import sys, time, logging
from pathlib import Path
from examples.fmu.build_fmu import build_acc_fmu
from tests.test_pipeline_black_box import fmu_vut, write_configs
from sumo_ayss.pipeline import load_pipeline, run_pipeline
import shutil


def main():
    tmp = Path("/tmp/h37/pp")
    shutil.rmtree(tmp)
    tmp.mkdir()
    c = build_acc_fmu(tmp / "c3.fmu", 3)
    which = sys.argv[1]
    from examples.fmu.build_fmu import build_python_fmu
    from tests.test_pipeline_black_box import process_vut

    vut = (
        fmu_vut(build_python_fmu(Path("examples/fmu/acc_slave.py"), tmp), 2.0)
        if which == "py"
        else None
        if which == "all"
        else process_vut(str(Path("examples/process_vut.py").resolve()))
    )
    vuts = {"v": vut}
    if which == "all":
        vuts = {
            "c": fmu_vut(build_acc_fmu(tmp / "c3.fmu", 3), 0.6),
            "p": process_vut(str(Path("examples/process_vut.py").resolve()), "--time-gap", "1.2"),
        }
    cfg = load_pipeline(write_configs(tmp, vuts))
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s %(message)s")
    t0 = time.time()
    statuses, report, *_ = run_pipeline(cfg, live=False)
    print("total", time.time() - t0, [s.state for s in statuses])


if __name__ == "__main__":
    main()

"""The bad-input corpus: every misuse a new user tried gives a clear one-line error.

Each case names the field, file or argument and what is allowed, exits non-zero from the
command line, and loses nothing already written. Cases that need SUMO use the real one (a
reset or a few steps); the run-folder cases share one tiny real training run.
"""

from __future__ import annotations

import io
import json
import math
import shutil
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml

from sumo_ayss.config import EnvConfig, SimConfig, load_experiment, read_yaml
from sumo_ayss.util.errors import ActionError, AyssError, CheckpointError, ConfigError
from sumo_ayss.vuts.controllers import ControllerError, bound_acceleration
from tests.helpers import TINY_AGENT

# ------------------------------------------------------------------------------ helpers


def _yaml(tmp_path: Path, text: str, name: str = "exp.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _one_line(err: BaseException) -> str:
    message = str(err)
    assert "\n" not in message.strip(), f"not one line: {message!r}"
    assert "Traceback" not in message
    return message


# ------------------------------------------------------------------ experiment files

EXPERIMENT_CASES: list[tuple[str, str, str]] = [
    # (id, YAML text, expected part of the message)
    (
        "inf time constant",
        "env: {actuator: {time_constant_s: .inf}}",
        "time_constant_s must be a finite",
    ),
    (
        "nan time constant",
        "env: {actuator: {time_constant_s: .nan}}",
        "time_constant_s must be a finite",
    ),
    ("inf alpha", "env: {reward: {alpha_adversarial: .inf}}", "alpha_adversarial must be a finite"),
    (
        "inf zero_m",
        "env: {reward: {same_lane: {zero_m: .inf}}}",
        "same_lane.zero_m must be a finite",
    ),
    ("-inf episode", "env: {episode_s: -.inf}", "env.episode_s must be a finite"),
    ("inf in a range", "env: {odd: {gap_m: [2, .inf]}}", "env.odd.gap_m[1] must be a finite"),
    (
        "odd above actuator top speed",
        "env: {odd: {pov_speed_mps: [10, 45]}}",
        "env.odd.pov_speed_mps max (45.0) must be <= env.actuator.max_speed_mps",
    ),
    (
        "buffer below batch",
        "agent: {buffer_size: 10, batch_size: 64}",
        "agent.buffer_size (10) must be >=",
    ),
    (
        "learning never starts",
        "agent: {learning_starts: 5000}\ntrain: {total_timesteps: 1000, eval_every: 500}",
        "agent.learning_starts (5000) must be < train.total_timesteps (1000)",
    ),
    ("duplicate key", "env:\n  case: car_following\n  case: cut_in\n", "duplicate key 'case'"),
    (
        "duplicate section",
        "train: {eval_every: 10}\ntrain: {eval_every: 20}\n",
        "duplicate key 'train'",
    ),
    ("empty file", "", "the file is empty"),
    ("only a comment", "# nothing\n", "the file is empty"),
    (
        "negative eval seed",
        "train: {eval_seed: -1}",
        "train.eval_seed must be an integer in [0, 2147483647]",
    ),
    ("huge eval seed", "train: {eval_seed: 99999999999}", "train.eval_seed must be an integer in"),
    (
        "extra_args not an option",
        "env: {sim: {extra_args: [foo]}}",
        "env.sim.extra_args must start",
    ),
    (
        "extra_args managed option",
        "env: {sim: {extra_args: ['--seed', '3']}}",
        "'--seed' is set by sumo_ayss",
    ),
    (
        "extra_args step length",
        "env: {sim: {extra_args: ['--step-length=0.1']}}",
        "env.sim.step_length_s",
    ),
    ("top level a list", "- 1\n- 2\n", "top level must be a mapping"),
    ("invalid YAML", "env: {case: [\n", "invalid YAML"),
    (
        "1000 m long vehicle",
        "env: {vuts: {long: {params: {length: 1000}}}, vut: long}",
        "env.vuts.long.params.length must be in (0, 30], got 1000.0; allowed: (0, 30] m",
    ),
    ("null VUT entry", "env: {vuts: {pi1: null}}", "env.vuts.pi1 is null"),
    ("null new VUT entry", "env: {vuts: {mine: null}, vut: mine}", "env.vuts.mine is null"),
]


@pytest.mark.parametrize(
    ("text", "expected"), [c[1:] for c in EXPERIMENT_CASES], ids=[c[0] for c in EXPERIMENT_CASES]
)
def test_bad_experiment_file_is_refused_by_name(tmp_path: Path, text: str, expected: str) -> None:
    with pytest.raises(ConfigError) as info:
        load_experiment(_yaml(tmp_path, text))
    assert expected in _one_line(info.value)


def test_network_that_is_not_a_sumo_network_is_refused_before_libsumo(tmp_path: Path) -> None:
    """libsumo segfaults on some XML files; they are refused in Python first."""
    routes = _yaml(tmp_path, '<routes><vType id="a"/></routes>\n', "routes.xml")
    with pytest.raises(
        ConfigError, match=r"env.network: .* is not a SUMO network \(root element <routes>"
    ):
        load_experiment(_yaml(tmp_path, f"env: {{network: {routes}}}"))
    garbage = _yaml(tmp_path, "this is not xml <", "garbage.net.xml")
    with pytest.raises(ConfigError, match=r"env.network: .* is not valid XML"):
        EnvConfig(network=garbage)
    empty = _yaml(tmp_path, "", "empty.net.xml")
    with pytest.raises(ConfigError, match=r"env.network: .* is not valid XML"):
        EnvConfig(network=empty)
    with pytest.raises(ConfigError, match=r"env\.network: file not found"):
        EnvConfig(network=tmp_path / "missing.net.xml")


_ROAD = (
    '<edge id="road" from="s" to="e">'
    '<lane id="road_0" index="0" speed="30" length="1000" shape="0,-1.6 1000,-1.6"/></edge>'
)
NETWORK_CASES: list[tuple[str, str, str, str]] = [
    # (id, case, <net> content, expected part of the message); libsumo segfaults on the
    # first two and raises a TraCIException ("Unknown edge 'road'") on the third.
    ("no lanes", "car_following", '<edge id="road" from="s" to="e"/>', "edge 'road' has no lanes"),
    (
        "a laneless extra edge",
        "car_following",
        _ROAD + '<edge id="x" from="s" to="e"></edge>',
        "edge 'x' has no lanes",
    ),
    ("no edges", "car_following", "", "has no edge 'road' (the road the envs drive on"),
    ("another edge", "car_following", _ROAD.replace('"road', '"street'), "has no edge 'road'"),
    ("one lane for cut-in", "cut_in", _ROAD, "edge 'road' has 1 lane(s), case 'cut_in' needs >= 2"),
]


@pytest.mark.parametrize(
    ("case", "content", "expected"),
    [c[1:] for c in NETWORK_CASES],
    ids=[c[0] for c in NETWORK_CASES],
)
def test_network_without_the_road_the_case_needs_is_refused(
    tmp_path: Path, case: str, content: str, expected: str
) -> None:
    net = _yaml(tmp_path, f'<net version="1.20">{content}</net>\n', "bad.net.xml")
    with pytest.raises(ConfigError) as info:
        load_experiment(_yaml(tmp_path, f"env: {{case: {case}, network: {net}}}"))
    message = _one_line(info.value)
    assert message.startswith(f"env.network: {net}") and expected in message


def test_the_built_in_networks_pass_the_network_check() -> None:
    from sumo_ayss.sim.network import NETWORK_DIR

    EnvConfig(case="car_following", network=NETWORK_DIR / "straight_2lane.net.xml")
    EnvConfig(case="cut_in", network=NETWORK_DIR / "straight_2lane.net.xml")
    EnvConfig(case="car_following", network=NETWORK_DIR / "straight_1lane.net.xml")


def test_yaml_reader_names_the_file_and_line_of_a_duplicate(tmp_path: Path) -> None:
    path = _yaml(tmp_path, "a: 1\nb: 2\na: 3\n")
    with pytest.raises(ConfigError) as info:
        read_yaml(path)
    message = _one_line(info.value)
    assert str(path) in message and "first at line 1" in message and "line 3" in message


def test_spcp_selection_without_signal_warns_naming_the_run(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """A cut-in ODD that pins the VUT at 0 m/s: every candidate scores 0 (no signal)."""
    from sumo_ayss.training.selection import select_spcp

    rows = [{"step": s, "mean_return": 0.0, "crash_rate": 0.0} for s in (200, 400, 600)]
    with caplog.at_level("WARNING"):
        choice = select_spcp(rows, run="runs/cut_in/pi1/seed_0")
    assert choice.index == 0 and choice.no_signal
    assert "no signal" in choice.reason
    assert "runs/cut_in/pi1/seed_0: all 3 SPCP candidates scored 0.0000" in caplog.text
    caplog.clear()
    rows[1]["mean_return"] = 0.5
    with caplog.at_level("WARNING"):
        choice = select_spcp(rows, run="runs/x")
    assert choice.index == 1 and not choice.no_signal and not caplog.text
    assert not select_spcp(rows[:1]).no_signal  # one candidate: nothing to compare


# ------------------------------------------------------------------ pipeline files

PIPELINE_CASES: list[tuple[str, str, str]] = [
    ("empty pipeline", "", "the file is empty"),
    ("no experiments", "experiments: {}", "experiments has no file for case 'car_following'"),
    (
        "unknown case in experiments",
        "grid: {cases: [car_following]}\nexperiments: {car_following: EXP, car_follow: EXP}",
        "experiments.car_follow: unknown case (did you mean 'car_following'?); allowed: "
        "['car_following', 'cut_in', 'lead_and_cut_in']",
    ),
    (
        "negative seed",
        "grid: {seeds: [0, -1]}",
        "grid.seeds[] must be an integer in [0, 2147483647], got -1",
    ),
    ("huge seed", "grid: {seeds: [4294967296]}", "grid.seeds[] must be an integer in"),
    ("duplicate grid", "grid: {seeds: [0]}\ngrid: {seeds: [1]}", "duplicate key 'grid'"),
    ("inf override", "total_timesteps: .inf", "total_timesteps must be an integer"),
    ("null VUT entry", "vuts: {mine: null}", "vuts.mine is null"),
]


@pytest.mark.parametrize(
    ("text", "expected"), [c[1:] for c in PIPELINE_CASES], ids=[c[0] for c in PIPELINE_CASES]
)
def test_bad_pipeline_file_is_refused_at_plan_time(
    tmp_path: Path, text: str, expected: str
) -> None:
    from sumo_ayss.pipeline import load_pipeline, plan_jobs

    exp = _yaml(tmp_path, yaml.safe_dump({"env": {"case": "car_following"}}), "cf.yaml")
    path = _yaml(tmp_path, text.replace("EXP", str(exp)), "pipeline.yaml")
    with pytest.raises(ConfigError) as info:
        plan_jobs(load_pipeline(path))
    assert expected in _one_line(info.value)


def test_pipeline_seed_override_out_of_range_is_refused(tmp_path: Path) -> None:
    from sumo_ayss.pipeline import load_pipeline

    path = _yaml(tmp_path, "grid: {seeds: [0]}", "pipeline.yaml")
    with pytest.raises(ConfigError, match=r"grid.seeds\[\] must be an integer in .*got -3"):
        load_pipeline(path, seeds=[1, -3])


def test_pipeline_without_a_config_argument_refuses_to_start(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from sumo_ayss.commands.pipeline import main

    with pytest.raises(SystemExit) as info:
        main([])
    assert info.value.code == 2
    assert "the following arguments are required: config" in capsys.readouterr().err


def test_pipeline_out_pointing_at_a_file_is_refused_before_any_job(tmp_path: Path) -> None:
    from sumo_ayss.commands.pipeline import main

    exp = _yaml(tmp_path, yaml.safe_dump({"env": {"case": "car_following"}}), "cf.yaml")
    file = _yaml(tmp_path, "precious\n", "results.txt")
    pipe = _yaml(
        tmp_path,
        yaml.safe_dump(
            {
                "grid": {"cases": ["car_following"], "vuts": ["pi1"], "seeds": [0]},
                "experiments": {"car_following": str(exp)},
                "out": str(file),
            }
        ),
        "pipeline.yaml",
    )
    with pytest.raises(SystemExit) as info:
        main([str(pipe), "--no-live"])
    assert isinstance(info.value.code, str) and "out: " in info.value.code
    assert "is a file" in info.value.code
    assert file.read_text() == "precious\n"  # nothing lost


# ------------------------------------------------------------------ train command line


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--seed", "-1"], "--seed must be an integer in [0, 2147483647], got -1"),
        (["--seed", "99999999999"], "--seed must be an integer in [0, 2147483647]"),
        (
            ["--total-timesteps", "500", "--eval-every", "500"],
            "agent.learning_starts (1000) must be < train.total_timesteps (500)",
        ),
        (["--vut", "pi9"], "env.vut must be one of"),
    ],
    ids=["negative seed", "huge seed", "learning never starts", "unknown vut"],
)
def test_bad_train_arguments_exit_with_one_line(
    tmp_path: Path, args: list[str], expected: str
) -> None:
    from sumo_ayss.train import main

    config = _yaml(tmp_path, "train: {progress_bar: false}\n", "experiment.yaml")
    with pytest.raises(SystemExit) as info:
        main(["--config", str(config), *args, "--out", str(tmp_path / "runs"), "--no-progress"])
    code = info.value.code
    assert isinstance(code, str) and code.startswith("error: ") and expected in code
    assert "\n" not in code
    assert not (tmp_path / "runs" / "car_following").exists()


def test_train_out_pointing_at_a_file_is_refused(tmp_path: Path) -> None:
    from sumo_ayss.train import main

    file = _yaml(tmp_path, "precious\n", "out.txt")
    config = _yaml(tmp_path, "train: {progress_bar: false}\n", "experiment.yaml")
    for out in (file, file / "below"):
        with pytest.raises(SystemExit) as info:
            main(["--config", str(config), "--out", str(out), "--no-progress"])
        assert isinstance(info.value.code, str) and "--out: " in info.value.code
        assert "is a file" in info.value.code
    assert file.read_text() == "precious\n"


def test_empty_experiment_file_refuses_to_train(tmp_path: Path) -> None:
    from sumo_ayss.train import main

    with pytest.raises(SystemExit) as info:
        main(["--config", str(_yaml(tmp_path, "")), "--out", str(tmp_path / "runs")])
    assert isinstance(info.value.code, str) and "the file is empty" in info.value.code


# ------------------------------------------------------------------ controllers


@pytest.mark.parametrize(
    "value",
    [math.nan, math.inf, -math.inf, None, "2.5", True, [1.0], {"a": 1}],
    ids=["nan", "inf", "-inf", "None", "str", "bool", "list", "dict"],
)
def test_controller_output_that_is_not_a_finite_number_is_refused(value: Any) -> None:
    with pytest.raises(ControllerError, match="must return a finite real number"):
        bound_acceleration(value, 3.0, 6.0)


def test_controller_numbers_of_numpy_and_int_types_are_accepted() -> None:
    import numpy as np

    assert bound_acceleration(np.float32(1.5), 3.0, 6.0) == 1.5
    assert bound_acceleration(np.int64(-9), 3.0, 6.0) == -6.0
    assert bound_acceleration(2, 3.0, 6.0) == 2.0


def test_a_controller_target_is_checked_before_it_is_called(tmp_path: Path) -> None:
    """Not a class, or a class without ``acceleration``: refused before anything runs."""
    from sumo_ayss.vuts.catalog import ControllerSpec

    marker = tmp_path / "ran"
    module = tmp_path / "odd_controllers.py"
    module.write_text(
        f"import pathlib\nMARK = pathlib.Path({str(marker)!r})\n"
        "def make(**kw):\n    MARK.touch()\n"
        "class NoAccel:\n    def __init__(self):\n        MARK.touch()\n"
        "class AccelNotCallable:\n    acceleration = 3.0\n"
        "    def __init__(self):\n        MARK.touch()\n"
    )
    cases = [
        ("subprocess:getoutput", {"cmd": f"touch {marker}"}, "is a function, not a class"),
        (f"{module}:make", {}, "is a function, not a class"),
        (f"{module}:MARK", {}, "is a PosixPath, not a class"),
        (f"{module}:NoAccel", {}, "has no acceleration(state) method"),
        (f"{module}:AccelNotCallable", {}, "has no acceleration(state) method"),
    ]
    for target, params, expected in cases:
        spec = ControllerSpec(target, 3.0, 6.0, params=params)
        with pytest.raises(ConfigError) as info:
            spec.build("env.vuts.mine.controller")
        message = _one_line(info.value)
        assert message.startswith(f"env.vuts.mine.controller.target {target!r}"), message
        assert expected in message and "(see sumo_ayss.vuts.controllers.Controller)" in message
        assert not marker.exists(), target  # nothing was called


class ReturnsNan:
    def acceleration(self, state: Any) -> float:
        return math.nan


class ReturnsString:
    def acceleration(self, state: Any) -> Any:
        return "2.5"


class Raises:
    def acceleration(self, state: Any) -> float:
        raise ZeroDivisionError("division by zero in my ACC")


def _controller_env(target: str) -> Any:
    from sumo_ayss.envs.car_following import CarFollowingEnv
    from sumo_ayss.vuts.catalog import ControllerSpec, VehicleType

    spec = ControllerSpec(target=target, max_accel_mps2=3.0, max_decel_mps2=6.0)
    vt = VehicleType(controller=spec)
    return CarFollowingEnv(EnvConfig(vuts={"mine": vt}, vut="mine"))


@pytest.mark.sumo
@pytest.mark.parametrize(
    ("target", "expected"),
    [
        ("tests.test_bad_inputs:ReturnsNan", "returned nan"),
        ("tests.test_bad_inputs:ReturnsString", "returned '2.5' (str)"),
        ("tests.test_bad_inputs:Raises", "raised ZeroDivisionError: division by zero in my ACC"),
    ],
    ids=["nan", "str", "raises"],
)
def test_a_misbehaving_controller_stops_the_episode_with_its_name(
    target: str, expected: str
) -> None:
    env = _controller_env(target)
    try:
        env.reset(seed=0)
        with pytest.raises(ControllerError) as info:
            env.step(0)
        message = _one_line(info.value)
        assert expected in message and target in message
    finally:
        env.close()


@pytest.mark.sumo
def test_a_controller_failure_in_a_pipeline_job_is_not_retried(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A controller that raises mid-run raises again on a retry (same seed, same path): the
    retry only delayed the pipeline's exit (by 18-40 s in the issue, 21.8 s measured)."""
    from sumo_ayss.commands.pipeline import run_pipeline
    from sumo_ayss.pipeline import load_pipeline

    module = tmp_path / "late.py"
    module.write_text(
        "class RaisesLater:\n    def __init__(self, after):\n        self.after = after\n"
        "        self.calls = 0\n    def acceleration(self, state):\n"
        "        self.calls += 1\n        if self.calls > self.after:\n"
        "            raise RuntimeError('late failure')\n        return 0.0\n"
    )
    controller = {"target": f"{module}:RaisesLater", "params": {"after": 150}}
    vut = {"controller": {**controller, "max_accel_mps2": 3.0, "max_decel_mps2": 6.0}}
    experiment = {
        "env": {"vut": "late", "vuts": {"late": vut}},
        "agent": TINY_AGENT,
        "train": {"total_timesteps": 600, "eval_every": 300, "n_eval_scenarios": 2},
    }
    exp = _yaml(tmp_path, yaml.safe_dump(experiment), "exp.yaml")
    pipeline = {
        "grid": {"cases": ["car_following"], "vuts": ["late"], "seeds": [0]},
        "experiments": {"car_following": str(exp)},
        "out": str(tmp_path / "runs"),
        "workers": 1,
        "retries": 1,
    }
    cfg = load_pipeline(_yaml(tmp_path, yaml.safe_dump(pipeline), "pipeline.yaml"))
    with caplog.at_level("INFO", logger="sumo_ayss.pipeline"):
        (status,), report, *_ = run_pipeline(cfg, live=False)
    assert status.state == "failed" and status.attempts == 1 and report is None
    assert status.error is not None and "ControllerError" in status.error
    assert "late failure" in status.error and "not retried" in caplog.text


# ------------------------------------------------------------------ env contract


@pytest.mark.sumo
@pytest.mark.parametrize(
    ("ic", "expected"),
    [
        ((math.nan, 20.0, 10.0), "pov_speed_mps must be a finite number"),
        ((20.0, -1.0, 10.0), "vut_speed_mps must be a finite number in [0, 50]"),
        ((20.0, 20.0, 1e6), "gap_m must be a finite number in [0, 500]"),
        ((20.0, 20.0, -3.0), "gap_m must be a finite number in [0, 500]"),
        ((45.0, 20.0, 10.0), "pov_speed_mps must be a finite number in [0, 40]"),
        ((20.0, math.inf, 10.0), "vut_speed_mps"),
    ],
    ids=["nan speed", "negative speed", "absurd gap", "overlap", "above actuator", "inf"],
)
def test_reset_refuses_an_unrealisable_initial_condition(
    ic: tuple[float, ...], expected: str
) -> None:
    from sumo_ayss.envs.car_following import CarFollowingEnv
    from sumo_ayss.envs.odd import InitialCondition

    env = CarFollowingEnv()
    try:
        with pytest.raises(ConfigError) as info:
            env.reset(options={"initial_condition": InitialCondition(*ic)})
        assert expected in _one_line(info.value)
        with pytest.raises(ConfigError, match="unknown keys"):
            env.reset(options={"initial_conditions": None})
    finally:
        env.close()


@pytest.mark.parametrize(
    "value",
    [-5, "x", 2**40, 2**31, True, 1.5, "3"],
    ids=["negative", "text", "2**40", "2**31", "bool", "float", "digit text"],
)
def test_a_bad_sumo_seed_is_refused_when_the_env_is_built(value: Any) -> None:
    from sumo_ayss.envs.car_following import CarFollowingEnv
    from sumo_ayss.envs.vec_env import PairVecEnv

    expected = f"sumo_seed must be an integer in [0, 2147483647] (SUMO's --seed), got {value!r}"
    for build in (
        lambda: CarFollowingEnv(sumo_seed=value),
        lambda: PairVecEnv(EnvConfig(), 2, sumo_seed=value),
    ):
        with pytest.raises(ConfigError) as info:
            build()
        assert expected in _one_line(info.value)


def test_sumo_seeds_at_the_ends_of_the_range_are_accepted() -> None:
    import numpy as np

    from sumo_ayss.envs.car_following import CarFollowingEnv
    from sumo_ayss.envs.vec_env import PairVecEnv

    for value in (0, 2**31 - 1, np.int64(7), None):
        env = CarFollowingEnv(sumo_seed=value)
        assert env.sumo_seed == value and (value is None or type(env.sumo_seed) is int)
        env.close()
        vec = PairVecEnv(EnvConfig(), 2, sumo_seed=value)
        assert vec.sumo_seed == value
        vec.close()


def test_bad_sumo_arguments_fail_with_a_simulation_error() -> None:
    from sumo_ayss.envs.car_following import CarFollowingEnv

    env = CarFollowingEnv(EnvConfig(sim=SimConfig(extra_args=("--no-such-option", "1"))))
    try:
        with pytest.raises(AyssError, match="SUMO failed to start"):
            env.reset(seed=0)
    finally:
        env.close()
    env = CarFollowingEnv()  # the failed start left no simulation behind
    try:
        env.reset(seed=0)
    finally:
        env.close()


# ------------------------------------------------------------------ run folders


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A real, tiny training run: (its experiment file, its run folder)."""
    from sumo_ayss.train import train

    root = tmp_path_factory.mktemp("bad_inputs_run")
    agent = {**TINY_AGENT, "learning_starts": 50}
    train_cfg = {
        "total_timesteps": 200,
        "eval_every": 100,
        "n_eval_scenarios": 2,
        "progress_bar": False,
    }
    exp = root / "tiny.yaml"
    exp.write_text(yaml.safe_dump({"agent": agent, "train": train_cfg}))
    run = train(load_experiment(exp), seed=0, out=root / "runs")
    return exp, run


def _copy_run(trained_run: tuple[Path, Path], tmp_path: Path) -> tuple[Path, Path]:
    _, run = trained_run
    out = tmp_path / "runs"
    copy = out / run.relative_to(run.parents[2])
    shutil.copytree(run, copy)
    return out, copy


def _truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: max(1, path.stat().st_size // 3)])


def _garbage(path: Path) -> None:
    path.write_bytes(b"\x00\xffnot what you expected\n" * 7)


Corruption = Callable[[Path], None]
RUN_CORRUPTIONS: list[tuple[str, str, Corruption, str]] = [
    # (id, file in the run folder, corruption, expected part of the message)
    ("truncated spcp.zip", "spcp.zip", _truncate, "spcp.zip: not a saved policy"),
    ("random spcp.zip", "spcp.zip", _garbage, "spcp.zip: not a saved policy"),
    ("garbage config.yaml", "config.yaml", _garbage, "config.yaml: unreadable run configuration"),
    (
        "config.yaml a list",
        "config.yaml",
        lambda p: p.write_text("- 1\n"),
        "config.yaml: unreadable",
    ),
    (
        "config.yaml bad value",
        "config.yaml",
        lambda p: p.write_text(p.read_text().replace("gamma: 0.8", "gamma: .inf")),
        "agent.gamma",
    ),
]


@pytest.mark.sumo
@pytest.mark.parametrize(
    ("name", "corrupt", "expected"),
    [c[1:] for c in RUN_CORRUPTIONS],
    ids=[c[0] for c in RUN_CORRUPTIONS],
)
def test_evaluate_on_a_corrupt_run_folder_gives_one_line(
    trained_run: tuple[Path, Path], tmp_path: Path, name: str, corrupt: Corruption, expected: str
) -> None:
    from sumo_ayss.evaluate import main

    _, run = _copy_run(trained_run, tmp_path)
    corrupt(run / name)
    with pytest.raises(SystemExit) as info:
        main([str(run), "--n-outcome", "2", "--n-ayss", "10", "--no-progress"])
    code = info.value.code
    assert isinstance(code, str) and expected in code and "\n" not in code
    assert not (run / "outcome.csv").exists()


@pytest.mark.sumo
@pytest.mark.parametrize(
    ("name", "corrupt", "expected"),
    [c[1:] for c in RUN_CORRUPTIONS[:3]],
    ids=[c[0] for c in RUN_CORRUPTIONS[:3]],
)
def test_replay_export_on_a_corrupt_run_folder_gives_one_line(
    trained_run: tuple[Path, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    name: str,
    corrupt: Corruption,
    expected: str,
) -> None:
    from sumo_ayss.replay import main

    _, run = _copy_run(trained_run, tmp_path)
    _write_outcome_table(run)
    corrupt(run / name)
    code = main(["export", str(run), "--outcome-row", "0", "--out", str(tmp_path / "scn")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and expected in err and len(err.splitlines()) == 1


def _write_outcome_table(run: Path) -> None:
    """Evaluate a copy of the run (tiny) so that outcome.csv exists for export."""
    from sumo_ayss.config import AyssConfig
    from sumo_ayss.evaluate import evaluate_run

    evaluate_run(run, n_outcome=2, ayss=AyssConfig(n_samples=10), progress=False)


RESUME_CORRUPTIONS: list[tuple[str, str, Corruption, str]] = [
    ("garbage latest.json", "checkpoints/latest.json", _garbage, "latest.json: unreadable JSON"),
    (
        "latest.json escapes",
        "checkpoints/latest.json",
        lambda p: p.write_text('{"dir": "../../x"}'),
        "must name a step_* folder",
    ),
    (
        "garbage state.json",
        "checkpoints/LATEST/state.json",
        _garbage,
        "state.json: unreadable JSON",
    ),
    (
        "state.json not a state",
        "checkpoints/LATEST/state.json",
        lambda p: p.write_text("[]"),
        "state.json: expected a JSON object, got list",
    ),
    (
        "state.json without counters",
        "checkpoints/LATEST/state.json",
        lambda p: p.write_text('{"next_eval": 4}'),
        "state.json: not a checkpoint state: missing field 'num_timesteps'",
    ),
    (
        "truncated model.zip",
        "checkpoints/LATEST/model.zip",
        _truncate,
        "model.zip: not a saved policy",
    ),
    (
        "truncated resume_model.zip",
        "checkpoints/LATEST/resume_model.zip",
        _truncate,
        "resume_model.zip: unreadable checkpoint",
    ),
    (
        "truncated replay.pkl",
        "checkpoints/LATEST/replay.pkl",
        _truncate,
        "replay.pkl: unreadable replay buffer",
    ),
    ("garbage config.yaml", "config.yaml", _garbage, "config.yaml: unreadable run configuration"),
    (
        "text in eval.csv",
        "eval.csv",
        lambda p: p.write_text(p.read_text().replace(",2,", ",two,", 1)),
        "eval.csv: column 'n_episodes', row 0: expected int, got 'two'",
    ),
    (
        "eval.csv not a table",
        "eval.csv",
        lambda p: p.write_text("hello\n1\n"),
        "eval.csv: missing column(s) ['step'",
    ),
]


@pytest.mark.sumo
@pytest.mark.parametrize(
    ("name", "corrupt", "expected"),
    [c[1:] for c in RESUME_CORRUPTIONS],
    ids=[c[0] for c in RESUME_CORRUPTIONS],
)
def test_resume_of_a_corrupt_run_folder_gives_one_line(
    trained_run: tuple[Path, Path], tmp_path: Path, name: str, corrupt: Corruption, expected: str
) -> None:
    from sumo_ayss.train import main

    exp, _ = trained_run
    out, run = _copy_run(trained_run, tmp_path)
    (run / "spcp.json").unlink()  # an unfinished run: --resume continues it
    latest = json.loads((run / "checkpoints" / "latest.json").read_text())["dir"]
    target = run / name.replace("LATEST", latest)
    corrupt(target)
    before = {p: p.read_bytes() for p in run.rglob("*") if p.is_file() and p != target}
    with pytest.raises(SystemExit) as info:
        main(["--config", str(exp), "--out", str(out), "--resume", "--no-progress"])
    code = info.value.code
    assert isinstance(code, str) and expected in code and "\n" not in code
    for path, data in before.items():  # nothing already written is lost or changed
        assert path.is_file() and path.read_bytes() == data, path


# ------------------------------------------------------------------ trust model


class _Boom:
    """Unpickling this runs code: it creates the file named in the class attribute."""

    marker = ""

    def __reduce__(self) -> Any:
        return (Path.touch, (Path(self.marker),))


def test_spcp_weights_are_never_unpickled(trained_run: tuple[Path, Path], tmp_path: Path) -> None:
    from sumo_ayss.agents.weights import read_policy_state

    _, run = _copy_run(trained_run, tmp_path)
    marker = tmp_path / "pwned"
    boom = _Boom()
    boom.marker = str(marker)
    evil = run / "spcp.zip"
    with zipfile.ZipFile(trained_run[1] / "spcp.zip") as src, zipfile.ZipFile(evil, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "policy.pth":
                buf = io.BytesIO()
                import torch as th

                th.save({"q_net.x": boom}, buf)
                data = buf.getvalue()
            dst.writestr(item, data)
    with pytest.raises(CheckpointError, match=r"policy\.pth is not a plain tensor state dict"):
        read_policy_state(evil)
    assert not marker.exists()


@pytest.mark.sumo
def test_a_run_folder_controller_is_imported_only_when_trusted(
    trained_run: tuple[Path, Path], tmp_path: Path
) -> None:
    from sumo_ayss.evaluate import main
    from sumo_ayss.run_folder import read_run

    _, run = _copy_run(trained_run, tmp_path)
    marker = tmp_path / "imported"
    module = tmp_path / "evil_controller.py"
    module.write_text(
        f"import pathlib\npathlib.Path({str(marker)!r}).touch()\n"
        "class C:\n    def acceleration(self, state):\n        return 0.0\n"
    )
    data = yaml.safe_load((run / "config.yaml").read_text())
    data["env"]["vut"] = "evil"
    data["env"]["vuts"]["evil"] = {
        "model": "IDM",
        "params": {},
        "description": "",
        "controller": {"target": f"{module}:C", "max_accel_mps2": 3.0, "max_decel_mps2": 6.0},
    }
    (run / "config.yaml").write_text(yaml.safe_dump(data))
    info = read_run(run)  # the config is read and checked, its controller not imported
    assert info.experiment.env.vut == "evil" and not marker.exists()
    with pytest.raises(SystemExit) as exit_info:
        main([str(run), "--n-outcome", "2", "--n-ayss", "10", "--no-progress"])
    assert isinstance(exit_info.value.code, str) and "--trust-controller" in exit_info.value.code
    assert not marker.exists()
    # Trusted: imported, and the evaluation runs.
    main([str(run), "--n-outcome", "2", "--n-ayss", "10", "--no-progress", "--trust-controller"])
    assert marker.exists() and (run / "outcome.csv").is_file()


# ------------------------------------------------------------------ report


def test_report_says_which_candidate_rows_it_dropped(
    trained_run: tuple[Path, Path], tmp_path: Path
) -> None:
    from sumo_ayss.run_folder import read_run

    _, run = _copy_run(trained_run, tmp_path)
    table = run / "eval.csv"
    lines = table.read_text().splitlines()
    head, first, *rest = lines
    cells = first.split(",")
    cells[1] = "oops"
    table.write_text("\n".join([head, ",".join(cells), *rest]) + "\n")
    loaded = read_run(run)
    assert loaded.eval_curve is not None and loaded.eval_curve.n_dropped == 1
    assert any("1 candidate row(s)" in p for p in loaded.problems)


def test_step_after_the_episode_ended_raises() -> None:
    from sumo_ayss.envs.car_following import CarFollowingEnv
    from sumo_ayss.envs.odd import InitialCondition

    env = CarFollowingEnv()
    try:
        env.reset(seed=0, options={"initial_condition": InitialCondition(0.0, 30.0, 0.5)})
        terminated = truncated = False
        while not (terminated or truncated):
            _, reward, terminated, truncated, _ = env.step(0)
        assert terminated and float(reward) < 0  # the collision
        with pytest.raises(ActionError, match="after the episode ended"):
            env.step(0)
        env.reset(seed=1)  # a reset makes it steppable again
        for _ in range(env.config.max_decisions):
            env.step(10)
        with pytest.raises(ActionError, match="call reset"):
            env.step(10)
    finally:
        env.close()


def test_report_out_pointing_at_a_file_is_refused(
    trained_run: tuple[Path, Path], tmp_path: Path
) -> None:
    from sumo_ayss.report.__main__ import main

    file = _yaml(tmp_path, "precious\n", "report.txt")
    with pytest.raises(SystemExit) as info:
        main([str(trained_run[1]), "--out", str(file)])
    assert isinstance(info.value.code, str) and "--out: " in info.value.code
    assert file.read_text() == "precious\n"


# ------------------------------------------------------------------ damaged case folders


def _garble(path: Path) -> None:
    path.write_bytes(b"\xff\xfe\x00garbled \x9c\x80 bytes\n" * 5)


def _cut(path: Path) -> None:
    data = path.read_bytes()
    path.write_bytes(data[: data.index(b",", len(data) // 2) + 1])  # a short last row


def _nan_cell(path: Path) -> None:
    lines = path.read_text().splitlines()
    head, first = lines[0].split(","), lines[1].split(",")
    first[head.index("episode_return")] = "nan"
    path.write_text("\n".join([lines[0], ",".join(first), *lines[2:]]) + "\n")


def _text_cell(path: Path) -> None:
    lines = path.read_text().splitlines()
    cells = lines[1].split(",")
    cells[1] = "oops"  # mean_return
    path.write_text("\n".join([lines[0], ",".join(cells), *lines[2:]]) + "\n")


def _header_only(path: Path) -> None:
    path.write_text(path.read_text().splitlines()[0] + "\n")


def _flat_returns(path: Path) -> None:
    """Every SPCP candidate scored 0.0 (a cut-in whose ODD pins the VUT's speed at 0)."""
    lines = path.read_text().splitlines()
    col = lines[0].split(",").index("mean_return")
    rows = [line.split(",") for line in lines[1:]]
    for r in rows:
        r[col] = "0.0"
    path.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")


def _keep_rows(path: Path, keep: Callable[[list[str], int], bool]) -> None:
    """Keep the rows ``keep(cells, index)`` of a CSV table (header kept)."""
    lines = path.read_text().splitlines()
    rows = [line for i, line in enumerate(lines[1:]) if keep(line.split(","), i)]
    path.write_text("\n".join([lines[0], *rows]) + "\n")


def _lose_vut(path: Path) -> None:
    """``crossplay.csv`` without any row driven against pi2."""
    _keep_rows(path, lambda cells, i: cells[0] != "pi2")


def _lose_one_row(path: Path) -> None:
    """``crossplay.csv`` less its very last row (one cell one scenario short)."""
    n = len(path.read_text().splitlines()) - 1
    _keep_rows(path, lambda cells, i: i != n - 1)


PI1 = "car_following/pi1/seed_0"
#: (id, file under the output folder, damage, expected part of the console warning); the
#: report and ``rank --no-run`` exit 0 with a warning on the console, and non-zero with
#: ``--strict``. ``config only`` is a half-written run folder (rank skips unfinished runs).
CASE_FOLDER_DAMAGE: list[tuple[str, str, Corruption, str]] = [
    ("garbled crossplay.csv", "car_following/crossplay.csv", _garble, "not UTF-8 text"),
    ("truncated crossplay.csv", "car_following/crossplay.csv", _cut, "cells, header has"),
    ("nan in crossplay.csv", "car_following/crossplay.csv", _nan_cell, "NaN not allowed"),
    ("text in eval.csv", f"{PI1}/eval.csv", _text_cell, "eval.csv: 1 candidate row(s)"),
    ("header-only ayss.csv", f"{PI1}/ayss.csv", _header_only, "ayss.csv: no rows"),
    ("every candidate the same", f"{PI1}/eval.csv", _flat_returns, "scored exactly the same"),
    ("one VUT's cross-play rows lost", "car_following/crossplay.csv", _lose_vut, "rows of VUT pi2"),
    (
        "one cross-play row lost",
        "car_following/crossplay.csv",
        _lose_one_row,
        "pi2/seed_1: 19 of 20",
    ),
    ("config only", "car_following/pi3/seed_0", lambda p: None, "eval.csv missing"),
]


def _case_folder(root: Path, name: str, damage: Corruption) -> Path:
    """A synthetic output folder (two VUTs, two seeds, a cross-play table), one file damaged."""
    from tests.report.test_report import make_crossplay, make_run

    for vut in ("pi1", "pi2"):
        for seed in (0, 1):
            make_run(root, "car_following", vut, seed)
    make_crossplay(root / "car_following", ["pi1", "pi2"], [0, 1])
    if name.startswith("car_following/pi3"):
        make_run(root, "car_following", "pi3", 0, files=("config",))
    damage(root / name)
    return root / name


@pytest.mark.parametrize(
    ("name", "damage", "expected"),
    [c[1:] for c in CASE_FOLDER_DAMAGE],
    ids=[c[0] for c in CASE_FOLDER_DAMAGE],
)
def test_report_warns_on_the_console_naming_a_damaged_file(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    name: str,
    damage: Corruption,
    expected: str,
) -> None:
    from sumo_ayss.report.__main__ import main

    root = tmp_path / "runs"
    damaged = _case_folder(root, name, damage)
    args = [str(root), "--out", str(tmp_path / "report"), "--n-boot", "100"]
    main(args)  # exit 0: the report is written, the problem is in it and on the console
    err = capsys.readouterr().err
    warned = [line for line in err.splitlines() if line.startswith("WARNING: ")]
    assert any(expected in line and str(damaged) in line for line in warned), err
    assert (tmp_path / "report" / "report.html").is_file()
    summary = (tmp_path / "report" / "summary.md").read_text(encoding="utf-8")
    gap = "No crossplay-mode rows for car_following: "  # the leaderboard says why, once
    no_rows = name.endswith("crossplay.csv") or name.endswith("pi3/seed_0")  # pi3: no rows
    assert summary.count(gap) == (1 if no_rows else 0), summary
    with pytest.raises(SystemExit) as info:
        main([*args, "--strict"])
    code = info.value.code
    assert isinstance(code, str) and "--strict" in code and "\n" not in code


def _rank_pipeline(tmp_path: Path) -> Path:
    from sumo_ayss.config import PROJECT_ROOT

    experiment = PROJECT_ROOT / "configs" / "car_following.yaml"
    grid = {"cases": ["car_following"], "vuts": ["pi1", "pi2"], "seeds": [0, 1]}
    pipeline = {"grid": grid, "experiments": {"car_following": str(experiment)}, "out": "runs"}
    return _yaml(tmp_path, yaml.safe_dump(pipeline), "pipeline.yaml")


@pytest.mark.parametrize(
    ("name", "damage", "expected"),
    [c[1:] for c in CASE_FOLDER_DAMAGE[:-1]],
    ids=[c[0] for c in CASE_FOLDER_DAMAGE[:-1]],
)
def test_rank_no_run_warns_on_the_console_naming_a_damaged_file(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    name: str,
    damage: Corruption,
    expected: str,
) -> None:
    from sumo_ayss.commands.rank import main

    damaged = _case_folder(tmp_path / "runs", name, damage)
    args = [str(_rank_pipeline(tmp_path)), "--no-run", "--no-live"]
    with pytest.raises(SystemExit) as info:
        main(args)
    assert info.value.code == 0
    err = capsys.readouterr().err
    warned = [line for line in err.splitlines() if line.startswith("WARNING: ")]
    assert any(expected in line and str(damaged) in line for line in warned), err
    with pytest.raises(SystemExit) as info:
        main([*args, "--strict"])
    assert info.value.code not in (0, None)
    md = (tmp_path / "runs" / "ranking.md").read_text(encoding="utf-8")
    if name.endswith("crossplay.csv"):  # the cross-play rows are missing, and it says why
        assert "| crossplay |" not in md
        why = [line for line in md.splitlines() if line.startswith("No crossplay-mode rows")]
        assert len(why) == 1 and "car_following" in why[0] and str(damaged) in why[0], md
        assert "exposure-mode rows stand in their place" in why[0]
    else:
        assert "| crossplay |" in md and "No crossplay-mode rows" not in md


def test_pipeline_warns_on_the_console_and_fails_under_strict(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The pipeline's end prints the analyses' problems as rank and report do (here the
    grid runner is replaced by the analyses it hands on: a run whose candidates all scored
    the same)."""
    import sumo_ayss.commands.pipeline as pipeline
    from sumo_ayss.pipeline import PipelineResult
    from sumo_ayss.rank import analyse

    damaged = _case_folder(tmp_path / "runs", f"{PI1}/eval.csv", _flat_returns)
    analyses = analyse(sorted((tmp_path / "runs").glob("*/*/seed_*")))
    result = PipelineResult([], None, [], analyses)
    monkeypatch.setattr(pipeline, "run_pipeline", lambda cfg, **kw: result)
    args = [str(_rank_pipeline(tmp_path)), "--no-live"]
    with pytest.raises(SystemExit) as info:
        pipeline.main(args)
    assert info.value.code == 0
    err = capsys.readouterr().err
    assert f"WARNING: {damaged}: all 20 SPCP candidates scored exactly the same" in err, err
    with pytest.raises(SystemExit) as info:
        pipeline.main([*args, "--strict"])
    assert isinstance(info.value.code, str) and "--strict: 1 problem(s)" in info.value.code


def test_a_garbled_table_or_json_file_is_a_table_error_naming_it(tmp_path: Path) -> None:
    from sumo_ayss.records.jsonio import read_json
    from sumo_ayss.records.table import read_table
    from sumo_ayss.run_folder import CROSSPLAY_SCHEMA
    from sumo_ayss.util.errors import TableError

    path = tmp_path / "crossplay.csv"
    _garble(path)
    with pytest.raises(TableError, match=r"crossplay\.csv: not UTF-8 text"):
        read_table(path, CROSSPLAY_SCHEMA)
    _garble(tmp_path / "crossplay.json")
    with pytest.raises(TableError, match=r"crossplay\.json: unreadable JSON: not UTF-8 text"):
        read_json(tmp_path / "crossplay.json")
    with pytest.raises(TableError, match="cannot read"):
        read_json(tmp_path)  # a folder
    from sumo_ayss.report.sections.discriminability import read_record

    _garble(tmp_path / "discriminability.json")
    assert read_record(tmp_path / "discriminability.json") is None  # logged, not raised


# ------------------------------------------------------------------ one writer per output folder


def _tiny_pipeline(tmp_path: Path) -> tuple[Path, Path]:
    """A one-job pipeline YAML and its output folder (the job is never run here)."""
    exp = _yaml(tmp_path, yaml.safe_dump({"env": {"case": "car_following"}}), "cf.yaml")
    out = tmp_path / "runs"
    grid = {"cases": ["car_following"], "vuts": ["pi1", "pi2"], "seeds": [0]}
    data = {"grid": grid, "experiments": {"car_following": str(exp)}, "out": str(out)}
    return _yaml(tmp_path, yaml.safe_dump(data), "pipeline.yaml"), out


def _default_sigint() -> None:
    """SIGINT back to its default in a child (ignored in a background test run)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_a_second_writer_on_a_locked_output_folder_is_refused_naming_the_holder(
    tmp_path: Path,
) -> None:
    import subprocess
    import sys

    from sumo_ayss.commands.pipeline import main as pipeline_main
    from sumo_ayss.commands.rank import main as rank_main

    pipe, out = _tiny_pipeline(tmp_path)
    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    try:
        out.mkdir()
        lock = out / "pipeline.lock"
        lock.write_text(f"{holder.pid}\n")
        for main in (pipeline_main, rank_main):
            with pytest.raises(SystemExit) as info:
                main([str(pipe), "--no-live"])
            code = info.value.code
            assert isinstance(code, str) and code.startswith("error: ") and "\n" not in code
            assert f"another pipeline (PID {holder.pid}) is writing this output folder" in code
        assert lock.read_text() == f"{holder.pid}\n"  # left to its holder
        assert sorted(p.name for p in out.iterdir()) == ["pipeline.lock"]  # nothing written
    finally:
        holder.kill()
        holder.wait()


def test_a_stale_lock_is_taken_over_with_a_log_line(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    import os
    import subprocess
    import sys

    from sumo_ayss.grid.folder_lock import output_lock

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    lock = tmp_path / "pipeline.lock"
    for stale in (f"{dead.pid}\n", "not a pid\n"):
        lock.write_text(stale)
        os.utime(lock, (0, 0))  # an old file, not one being written now
        with caplog.at_level("WARNING"), output_lock(tmp_path) as held:
            assert held == lock.resolve() and lock.read_text() == f"{os.getpid()}\n"
        assert "taking over the stale lock" in caplog.text
        assert not lock.exists()  # released at the end
    assert f"PID {dead.pid} no longer runs" in caplog.text
    with pytest.raises(RuntimeError), output_lock(tmp_path):
        raise RuntimeError("a failing stage")
    assert not lock.exists()  # released on an exception


@pytest.mark.parametrize("signum", ["SIGINT", "SIGTERM"])
def test_two_processes_one_lock_released_on_a_signal(tmp_path: Path, signum: str) -> None:
    import signal
    import subprocess
    import sys

    from sumo_ayss.grid.folder_lock import output_lock
    from sumo_ayss.util.errors import LockError

    code = (
        "import sys, time\nfrom sumo_ayss.grid.folder_lock import output_lock\n"
        "with output_lock(sys.argv[1]):\n    print('held', flush=True)\n    time.sleep(60)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code, str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_sigint,
    )
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
        with pytest.raises(LockError, match=f"PID {proc.pid}"), output_lock(tmp_path):
            pass
        proc.send_signal(getattr(signal, signum))
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert not (tmp_path / "pipeline.lock").exists()
    with output_lock(tmp_path):  # free again
        pass

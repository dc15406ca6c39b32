"""PairVecEnv: many VUT-POV pairs in one SUMO simulation, against the single env.

Equivalence tolerance: exact. Observations (bytes), rewards (the vec env's float32 equals
the single env's reward cast to float32), terminations, truncations, terminal observations
and every info value are bit-identical, except cut-in's world y positions (offset by
exactly -50 m per road, to 1e-9 m) and Δv̄ computed from them (1e-9 m/s).
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import sumolib
import yaml
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import VecCheckNan, VecEnv, VecMonitor
from stable_baselines3.common.vec_env.util import obs_space_info

from sumo_ayss.agents import AyssDQN
from sumo_ayss.agents.hparams import DQNHyperParams
from sumo_ayss.config import ActuatorConfig, EnvConfig, SimConfig, load_experiment
from sumo_ayss.envs import make_env
from sumo_ayss.envs.cut_in import LANE_CHANGE
from sumo_ayss.envs.odd import InitialCondition, sample_initial_conditions
from sumo_ayss.envs.vec_env import PairVecEnv
from sumo_ayss.run_folder import read_eval_table
from sumo_ayss.scenarios.rollout import run_episodes
from sumo_ayss.sim.network import (
    NETWORK_DIR,
    PARALLEL_ROAD_SPACING_M,
    build_parallel_network,
    parallel_road_edge,
)
from sumo_ayss.training.trainer import Trainer, evaluate_on_vec, hparams_for_n_envs, train
from sumo_ayss.util.errors import ActionError, ConfigError
from tests.helpers import TINY_AGENT

pytestmark = pytest.mark.sumo

#: Keys whose values hold world y (offset per road) or are computed from them.
WORLD_Y_KEYS = ("pov_y_m", "vut_y_m")
WORLD_Y_DERIVED = ("delta_v_bar_mps",)
TOL = 1e-9


@pytest.fixture
def closing() -> Iterator[Any]:
    """``closing(x)`` returns ``x`` and closes it after the test (one SUMO per process)."""
    made: list[Any] = []

    def track(obj: Any) -> Any:
        made.append(obj)
        return obj

    try:
        yield track
    finally:
        for obj in reversed(made):
            obj.close()


@pytest.fixture
def make_vec(closing) -> Any:
    """``make_vec(config, n, **kwargs)``: a PairVecEnv closed after the test."""

    def make(config: EnvConfig | None = None, n: int = 4, **kwargs: Any) -> PairVecEnv:
        return closing(PairVecEnv(config, n, **kwargs))  # type: ignore[no-any-return]

    return make


def random_actions(case: str, steps: int, n: int, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n_actions = 21 if case == "car_following" else 42
    actions = rng.integers(0, n_actions, size=(steps, n))
    if case == "cut_in":  # lane changes often enough to see cut-ins and side-swipes
        actions[rng.random((steps, n)) < 0.15] = LANE_CHANGE
    return actions


def assert_info_equal(
    single: dict[str, Any], vec: dict[str, Any], road: int, exact: bool = True
) -> None:
    """Equal infos; ``exact=False``: floats to ``TOL`` (highway-env's lateral state is
    integrated in world y, which differs per road, so it rounds differently per road)."""
    vec = {k: v for k, v in vec.items() if k not in ("terminal_observation", "TimeLimit.truncated")}
    assert single.keys() == vec.keys()
    for key, a in single.items():
        b = vec[key]
        if key in WORLD_Y_KEYS:
            assert b - a == pytest.approx(-PARALLEL_ROAD_SPACING_M * road, abs=TOL), key
        elif not exact and isinstance(a, float):
            assert a == b or (math.isnan(a) and math.isnan(b)) or abs(a - b) <= TOL, (key, a, b)
        elif key in WORLD_Y_DERIVED:
            assert (math.isnan(a) and math.isnan(b)) or abs(a - b) <= TOL, key
        else:
            assert type(a) is type(b) and a == b, (key, a, b)


# ---------------------------------------------------------------------- network


def test_parallel_network_copies_the_built_in_road(tmp_path: Path) -> None:
    net = sumolib.net.readNet(str(build_parallel_network(3, 2, tmp_path)))
    builtin = sumolib.net.readNet(str(NETWORK_DIR / "straight_2lane.net.xml")).getEdge("road")
    assert len(net.getEdges()) == 3
    for i in range(3):
        edge = net.getEdge(parallel_road_edge(i))
        assert edge.getFromNode().getID() == f"s{i}"  # no node shared with another road
        for lane, ref in zip(edge.getLanes(), builtin.getLanes(), strict=True):
            assert lane.getLength() == ref.getLength() and lane.getSpeed() == ref.getSpeed()
            assert lane.getWidth() == ref.getWidth()
            shifted = [(x, y - PARALLEL_ROAD_SPACING_M * i) for x, y in ref.getShape()]
            np.testing.assert_allclose(lane.getShape(), shifted, atol=1e-9)


# ---------------------------------------------------------------------- equivalence


def fidelity_config(case: str) -> EnvConfig:
    """highway-env's laws for VUT and POV (paper-fidelity mode)."""
    return EnvConfig(
        case=case,  # type: ignore[arg-type]
        vut="hwenv_pi1",
        actuator=ActuatorConfig(mode="highway_env"),
        sim=SimConfig(lateral_resolution_m=0.1 if case == "cut_in" else None),
    )


@pytest.mark.parametrize("fidelity", [False, True], ids=["sumo", "hwenv"])
@pytest.mark.parametrize("case", ["car_following", "cut_in"])
def test_each_pair_reproduces_the_single_env_exactly(
    make_vec, closing, case: str, fidelity: bool
) -> None:
    """Same seeds and actions: identical trajectories, across auto-resets and collisions."""
    n, steps, seed, sumo_seed = 3, 160, 100, 5
    config = fidelity_config(case) if fidelity else EnvConfig(case=case)
    actions = random_actions(case, steps, n)
    vec = make_vec(config, n, sumo_seed=sumo_seed)
    vec.seed(seed)
    first = vec.reset()
    # vec_steps[i]: (obs, reward, done, truncated, info) per step of pair i
    vec_steps: list[list[tuple[Any, ...]]] = [[] for _ in range(n)]
    next_obs: list[list[np.ndarray]] = [[first[i]] for i in range(n)]
    for t in range(steps):
        obs, rewards, dones, infos = vec.step(actions[t])
        for i in range(n):
            last = infos[i]["terminal_observation"] if dones[i] else obs[i]
            trunc = infos[i]["TimeLimit.truncated"]
            vec_steps[i].append((last, rewards[i], dones[i], trunc, infos[i]))
            if dones[i]:
                next_obs[i].append(obs[i])  # the next episode's first observation
    vec.close()

    collisions = truncations = 0
    for i in range(n):
        env = closing(make_env(config, sumo_seed=sumo_seed))
        obs, _ = env.reset(seed=seed + i)
        starts = [obs]
        for t in range(steps):
            obs, reward, terminated, truncated, info = env.step(int(actions[t, i]))
            v_obs, v_reward, v_done, v_trunc, v_info = vec_steps[i][t]
            if fidelity:
                np.testing.assert_allclose(obs, v_obs, atol=1e-5)
                assert np.float32(reward) == pytest.approx(v_reward, abs=1e-6)
            else:
                assert obs.tobytes() == v_obs.tobytes(), (i, t)
                assert np.float32(reward) == v_reward
            assert (terminated or truncated) == v_done and truncated == v_trunc
            assert_info_equal(info, v_info, road=i, exact=not fidelity)
            collisions += terminated
            truncations += truncated
            if terminated or truncated:
                obs, _ = env.reset()
                starts.append(obs)
        env.close()
        assert [o.tobytes() for o in starts] == [o.tobytes() for o in next_obs[i]]
    # both ways an episode ends were exercised (highway-env's IDM VUT does not collide in
    # car-following under these random actions)
    assert collisions >= (0 if fidelity and case == "car_following" else 1)
    assert truncations >= 3


def test_decisions_spanning_several_sumo_steps_match_too(make_vec, closing) -> None:
    """0.4 s decisions (2 SUMO steps): a pair that collides mid-decision stops there."""
    config = EnvConfig(case="cut_in", decision_period_s=0.4, episode_s=4.0)
    n, steps = 2, 60
    actions = random_actions("cut_in", steps, n, seed=5)
    vec = make_vec(config, n, sumo_seed=1)
    vec.seed(7)
    vec.reset()
    rows = [vec.step(actions[t]) for t in range(steps)]
    vec.close()
    collisions = 0
    for i in range(n):
        env = closing(make_env(config, sumo_seed=1))
        env.reset(seed=7 + i)
        for t in range(steps):
            obs, reward, terminated, truncated, info = env.step(int(actions[t, i]))
            v_obs, v_rewards, v_dones, v_infos = rows[t]
            last = v_infos[i]["terminal_observation"] if v_dones[i] else v_obs[i]
            assert obs.tobytes() == last.tobytes() and np.float32(reward) == v_rewards[i]
            assert_info_equal(info, v_info := v_infos[i], road=i)
            assert v_dones[i] == (terminated or truncated) and v_info["TimeLimit.truncated"] == (
                truncated
            )
            collisions += terminated
            if terminated or truncated:
                env.reset()
        env.close()
    assert collisions >= 1


# ---------------------------------------------------------------------- isolation, resets


def test_pairs_never_interact(make_vec) -> None:
    """A crash on one road changes nothing on the others; every pair stays on its road."""
    calm = InitialCondition(20.0, 20.0, 15.0)
    crash = InitialCondition(20.0, 30.0, 2.0)  # fast VUT, 2 m behind a POV about to brake
    hold, stop = 2, 0

    def run(middle: InitialCondition) -> tuple[list[Any], list[bool]]:
        vec = make_vec(EnvConfig(), 3, sumo_seed=0)
        vec.set_options([{"initial_condition": ic} for ic in (calm, middle, calm)])
        vec.reset()
        outer, middle_collided = [], []
        for _ in range(20):
            obs, _, dones, infos = vec.step(np.array([hold, stop, hold]))
            outer.append((obs[[0, 2]].tobytes(), [infos[i]["vut_accel_mps2"] for i in (0, 2)]))
            middle_collided.append(bool(infos[1]["collision"]))
            for i, env in enumerate(vec.envs):
                pair = env._pair
                assert pair is not None
                for _x, y in pair.positions_xy():
                    assert abs(y + PARALLEL_ROAD_SPACING_M * i) < 10.0  # on its own road
            assert not dones[[0, 2]].any()
        vec.close()
        return outer, middle_collided

    quiet, no_crash = run(calm)
    loud, crashed = run(crash)
    assert not any(no_crash) and any(crashed)
    assert quiet == loud


def test_auto_reset_gives_terminal_observation_and_new_episode(make_vec) -> None:
    vec = make_vec(EnvConfig(), 2, sumo_seed=0)
    vec.set_options([{"initial_condition": InitialCondition(20.0, 30.0, 2.0)}, {}])
    vec.seed(11)
    vec.reset()
    stop = np.array([0, 2])
    saw_collision = saw_time_limit = False
    for _ in range(60):
        obs, rewards, dones, infos = vec.step(stop)
        for i in np.flatnonzero(dones):
            info = infos[i]
            terminal = info["terminal_observation"]
            assert terminal.shape == obs[i].shape and terminal.dtype == np.float32
            assert terminal[2] == np.float32(min(max(info["headway_m"], -20.0), 500.0))
            ic = vec.reset_infos[i]["initial_condition"]  # the new episode, sampled
            np.testing.assert_allclose(obs[i], ic.as_tuple(), atol=1e-4)
            if info["collision"]:
                saw_collision = True
                assert not info["TimeLimit.truncated"]
                assert rewards[i] == vec.config.reward.min_reward
            else:
                saw_time_limit = True
                assert info["TimeLimit.truncated"]
        assert all("terminal_observation" not in infos[i] for i in np.flatnonzero(~dones))
    assert saw_collision and saw_time_limit


# ---------------------------------------------------------------------- the VecEnv contract


def test_vec_env_api(make_vec) -> None:
    n = 4
    vec = make_vec(EnvConfig(case="cut_in"), n)
    assert isinstance(vec, VecEnv) and vec.num_envs == n
    keys, shapes, dtypes = obs_space_info(vec.observation_space)
    assert keys == [None] and shapes[None] == (4,) and dtypes[None] == np.float32
    with pytest.raises(ActionError, match="reset"):
        vec.step(np.zeros(n, dtype=np.int64))
    assert vec.seed(5) == [5, 6, 7, 8]
    obs = vec.reset()
    assert obs.shape == (n, 4) and obs.dtype == np.float32
    assert all(vec.observation_space.contains(o) for o in obs)
    assert vec.sumo_seed == 5  # from the first reset's seed
    assert len({ic.as_tuple() for ic in vec.initial_conditions if ic is not None}) == n

    actions = np.array([vec.action_space.sample() for _ in range(n)])
    vec.step_async(actions)
    obs, rewards, dones, infos = vec.step_wait()
    assert obs.shape == (n, 4) and rewards.shape == (n,) and rewards.dtype == np.float32
    assert dones.shape == (n,) and dones.dtype == bool
    assert isinstance(infos, list) and len(infos) == n
    assert all("TimeLimit.truncated" in info for info in infos)

    before = [env._k for env in vec.envs]
    for bad in (np.array([0, 1, 2, 42]), np.array([0, 1, 2]), np.array([0.0, 1.0, 2.0, 3.0])):
        with pytest.raises(ActionError):
            vec.step(bad)
    assert [env._k for env in vec.envs] == before  # a bad batch moved no one

    assert vec.get_attr("CASE") == ["cut_in"] * n
    vec.set_attr("tag", "x", indices=[1, 3])
    assert vec.get_attr("tag", indices=[1, 3]) == ["x", "x"]
    assert vec.env_method("_validate_action", 3, indices=0) == [3]
    assert vec.env_is_wrapped(Monitor) == [False] * n
    with pytest.raises(ActionError, match="member of a PairVecEnv"):
        vec.env_method("step", 1, indices=2)
    with pytest.raises(ActionError, match="member of a PairVecEnv"):
        vec.env_method("reset", indices=2)

    wrapped = VecCheckNan(VecMonitor(vec), raise_exception=True)
    wrapped.reset()
    episodes = []
    for _ in range(60):
        _, _, _, infos = wrapped.step(np.array([wrapped.action_space.sample() for _ in range(n)]))
        episodes += [info["episode"] for info in infos if "episode" in info]
    assert episodes and all(1 <= ep["l"] <= 25 for ep in episodes)
    vec.close()
    vec.close()  # twice is safe


def test_bad_configuration_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="n_envs"):
        PairVecEnv(EnvConfig(), 0)
    net = NETWORK_DIR / "straight_1lane.net.xml"  # a valid network: the vec env builds its own
    with pytest.raises(ConfigError, match="network"):
        PairVecEnv(EnvConfig(network=net), 2)


# ---------------------------------------------------------------------- evaluation, training


def test_scenario_evaluation_on_pairs_equals_the_single_env(make_vec, closing) -> None:
    """``evaluate_on_vec`` tabulates exactly what ``run_episodes`` does on one env."""
    config = EnvConfig(case="cut_in")
    scenarios = sample_initial_conditions(config.odd, 11, seed=4)

    def policy(obs: np.ndarray) -> np.ndarray:  # cut in when close, else drive 15 m/s
        return np.where(obs[:, 2] < 8.0, LANE_CHANGE, 16).astype(np.int64)

    single = closing(make_env(config, sumo_seed=0))
    expected = run_episodes(single, policy, scenarios)
    single.close()
    vec = make_vec(config, 4, sumo_seed=0)
    got = evaluate_on_vec(vec, policy, scenarios)
    with pytest.raises(ActionError, match="reset"):
        vec.step(np.zeros(4, dtype=np.int64))  # the training episodes were abandoned
    assert got == expected
    assert any(r.lane_changed for r in got) and any(r.collided for r in got)


def test_hparams_keep_gradient_steps_per_transition() -> None:
    hp = DQNHyperParams()  # 1 gradient step per 4 transitions
    assert hparams_for_n_envs(hp, 1) is hp
    for n in (2, 3, 8, 32):
        scaled = hparams_for_n_envs(hp, n)
        assert scaled.gradient_steps / (scaled.train_freq * n) == hp.update_to_data_ratio
    assert (hparams_for_n_envs(hp, 8).train_freq, hparams_for_n_envs(hp, 8).gradient_steps) == (
        1,
        2,
    )


TINY = TINY_AGENT


def test_dqn_learns_on_four_pairs(make_vec) -> None:
    vec = make_vec(EnvConfig(), 4, sumo_seed=0)
    hp = hparams_for_n_envs(DQNHyperParams(**{**TINY, "learning_starts": 200}), 4)
    model = AyssDQN(VecMonitor(vec), hp, seed=0)
    model.learn(total_timesteps=600)
    assert model.num_timesteps == 600 and model._n_updates > 0
    assert model.replay_buffer.size() == 600 // 4  # rows of 4 transitions
    assert model.ep_info_buffer  # VecMonitor reported finished episodes


def test_training_with_n_envs_evaluates_cuts_and_resumes(tmp_path: Path, closing) -> None:
    data = {
        "agent": TINY,
        "train": {
            "n_eval_scenarios": 10,
            "progress_bar": False,
            "total_timesteps": 400,
            "eval_every": 200,
            "n_envs": 4,
        },
    }
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(data))
    cfg = load_experiment(tmp_path / "c.yaml")
    run_dir = tmp_path / "runs" / "car_following" / "pi1" / "seed_1"
    trainer = closing(Trainer(cfg, 1, run_dir))
    trainer.write_metadata([])
    trainer.new_model()
    trainer.learn(progress_bar=False)
    model, vec = trainer.model, trainer.pair_vec
    assert model is not None and vec is not None
    assert (model.train_freq.frequency, model.gradient_steps) == (1, 1)  # 1 per 4 transitions
    buffer = model.replay_buffer
    row = 200 // 4 - 1  # the vec step at which the first candidate was evaluated
    assert buffer.dones[row].all()  # every pair's episode ended there ...
    assert buffer.timeouts[row].sum() >= 3  # ... mostly cut as time-limit truncations
    trainer.select()
    saved = [ic.as_tuple() for ic in vec.initial_conditions if ic is not None]
    trainer.close()
    rows = read_eval_table(run_dir / "eval.csv")
    assert [r["step"] for r in rows] == [200, 400] and all(r["n_episodes"] == 10 for r in rows)
    state = json.loads((run_dir / "checkpoints" / "step_000000400" / "state.json").read_text())
    assert len(state["env_rngs"]) == 4

    resumed = closing(Trainer(cfg, 1, run_dir))
    resumed.resume()
    vec = resumed.pair_vec
    assert vec is not None
    assert [ic.as_tuple() for ic in vec.initial_conditions if ic is not None] == saved
    assert [env.np_random.bit_generator.state for env in vec.envs] == state["env_rngs"]


def test_n_envs_one_keeps_the_single_env(tmp_path: Path, closing) -> None:
    cfg = load_experiment(None)
    assert cfg.train.n_envs == 1
    trainer = closing(Trainer(cfg, 0, tmp_path))
    assert trainer.env is not None and trainer.pair_vec is None
    with pytest.raises(ConfigError, match="n_envs"):
        dataclasses.replace(cfg.train, n_envs=0)


def test_train_entry_point_with_n_envs(tmp_path: Path) -> None:
    data = {"agent": TINY, "train": {"n_eval_scenarios": 5, "progress_bar": False}}
    data["train"].update(total_timesteps=240, eval_every=120, n_envs=8)
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(data))
    cfg = load_experiment(tmp_path / "c.yaml").with_vut("pi2")
    cfg = dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, case="cut_in"))
    run = train(cfg, seed=2, out=tmp_path / "runs")
    rows = read_eval_table(run / "eval.csv")
    assert [r["step"] for r in rows] == [120, 240]
    assert (run / "spcp.json").is_file()

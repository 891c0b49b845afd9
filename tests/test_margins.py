"""Time-domain margins (lvgym.benchmark.perturb, lvgym.benchmark.margins; the command lvgym.cli.margins): the
gain and the delay between policy and actuator, the bisection, the bound, and a short end-to-end run."""

import json
import math

import numpy as np
import pytest

import lvgym.cli.policies  # noqa: F401  (registers the built-in policies: pid)
from lvgym.benchmark import ledger
from lvgym.benchmark import get_suite
from lvgym.benchmark.margins import (EXPERIMENTS, RATE_ERROR_FLOOR_RADPS, RATE_LIMIT_FLOOR_S, MarginOptions, _summary, bounds,
                                     margins_table, time_domain_margins, verdict)
from lvgym.benchmark.perturb import db_to_gain, find_threshold, gain_to_db
from lvgym.benchmark.rows import OneRowEnv, RowDelay, scaled
from lvgym.benchmark.registry import POLICIES
from lvgym.benchmark.suites import Condition
from lvgym.cli.margins import main
from lvgym.simulator.layouts import ACTUATOR

SHORT = 8.0          # s of mission of the end-to-end runs (the controller is on from 2 s)


class Fixed:
    """A policy that says the same action every step."""

    name = "fixed"

    def __init__(self, action):
        self.action = np.asarray(action)
        self.resets = 0

    def reset(self):
        self.resets += 1

    def act(self, observation, info):
        return self.action.copy()


def test_the_gain_multiplies_each_rows_action():
    a = np.array([[0.3, -0.5], [0.25, 1.0]], dtype=np.float32)
    doubled = scaled(a, np.array([2.0, 0.5]), "fixed")
    assert doubled.dtype == np.float32
    np.testing.assert_allclose(doubled, [[0.6, -1.0], [0.125, 0.5]], rtol=1e-7)
    assert scaled(a, np.zeros(2), "fixed").tolist() == [[0.0, 0.0], [0.0, 0.0]]
    with pytest.raises(ValueError, match="Box"):
        scaled(np.array([[1, 2]]), np.array([2.0]), "fixed")
    assert db_to_gain(20.0) == pytest.approx(10.0) and db_to_gain(-6.0) == pytest.approx(0.501187, rel=1e-5)
    assert gain_to_db(0.5) == pytest.approx(-6.0206, abs=1e-4) and gain_to_db(0.0) == -math.inf


def _open_loop_run(env, actions, seed=3, servo_delay=None, delay_steps=0):
    """Commands and gimbal angles per control step of an open-loop action sequence, delayed by ``delay_steps``
    physics steps (:class:`RowDelay` over the single env as a batch of one row)."""
    one = OneRowEnv(env)
    one.reset(seed=[seed])
    if servo_delay is not None:
        ACTUATOR.view(env.unwrapped.state.sim.actuator, "delay")[0, 0] = servo_delay
    delay = RowDelay(one, [delay_steps]) if delay_steps else None
    commands, gimbals = [], []
    for a in actions:
        *_, terminated, truncated, info = one.step(a[None] if delay is None else delay.apply(a[None]))
        commands.append(ACTUATOR.view(env.unwrapped.state.sim.actuator, "command")[0].copy())
        gimbals.append(np.asarray(info["gimbal"][0]).copy())
        if terminated[0] or truncated[0]:
            break
    return np.array(commands), np.array(gimbals)


@pytest.fixture(scope="module")
def open_loop_env():
    """SmileAscent-v1, rigid, no dispersion, the controller on from the start (no masked commands), 1 s."""
    cond = Condition("t", "lvgym/SmileAscent-v1", model="rigid",
                     options=(("controller_on_after_s", 0.0), ("mission_time_s", 1.0)))
    return cond.make_env()


def test_delay_shifts_the_commands_by_whole_periods(open_loop_env):
    env = open_loop_env
    actions = np.random.default_rng(1).uniform(-1.0, 1.0, (50, 2)).astype(np.float32)
    c0, g0 = _open_loop_run(env, actions)
    per = env.unwrapped.task.substeps
    assert per == 2 and len(c0) == 50
    for periods in (1, 2, 3):
        c, _ = _open_loop_run(env, actions, delay_steps=periods * per)
        np.testing.assert_array_equal(c[periods:], c0[:-periods])
        np.testing.assert_array_equal(c[:periods], 0.0)           # the buffer starts neutral


def test_delay_of_single_physics_steps_goes_to_the_servo(open_loop_env):
    env = open_loop_env
    actions = np.random.default_rng(2).uniform(-1.0, 1.0, (50, 2)).astype(np.float32)
    c0, g0 = _open_loop_run(env, actions)
    c1, g1 = _open_loop_run(env, actions, delay_steps=1)
    assert ACTUATOR.view(env.unwrapped.state.sim.actuator, "delay")[0, 0] == 1.0
    np.testing.assert_array_equal(c1, c0)                          # the command is on time ...
    assert not np.array_equal(g1, g0)                              # ... the servo follows it 10 ms late
    # a whole period through the servo's delay field is the same pure shift as a period in the buffer
    _, g_servo = _open_loop_run(env, actions, servo_delay=2)
    _, g_buffer = _open_loop_run(env, actions, delay_steps=2)
    np.testing.assert_array_equal(g_servo, g_buffer)
    one = OneRowEnv(env)
    one.reset(seed=[3])
    with pytest.raises(ValueError, match="whole numbers"):
        RowDelay(one, [1.5])


def test_delay_adds_to_the_dispersed_servo_delay():
    env = Condition("t", "lvgym/SmileAscent-v1", model="rigid", randomize=("servo_delay",),
                    options=(("mission_time_s", 0.1),)).make_env()
    one = OneRowEnv(env)
    dispersed = {}
    for seed in range(8):
        one.reset(seed=[seed])
        dispersed[seed] = int(ACTUATOR.view(env.unwrapped.state.sim.actuator, "delay")[0, 0])
    assert set(dispersed.values()) == {0, 1}
    for seed, d0 in dispersed.items():
        one.reset(seed=[seed])
        delay = RowDelay(one, [1])
        field = int(ACTUATOR.view(env.unwrapped.state.sim.actuator, "delay")[0, 0])
        assert field + 2 * int(delay.length[0]) == d0 + 1 and field < 2


def test_search_finds_a_known_threshold():
    calls = []

    def below(x):
        calls.append(x)
        return x < 7.3

    passed, failed, trials = find_threshold(below, 0.0, 20.0, 0.25, 1.0)
    assert passed < 7.3 <= failed and failed - passed <= 0.25 and [v for v, _ in trials] == calls
    assert calls[:4] == [1.0, 3.0, 7.0, 15.0] and len(calls) == 9         # outwards, doubling, then bisection
    # downwards (a gain lowered): the threshold at -13.1 dB
    passed, failed, trials = find_threshold(lambda x: x > -13.1, 0.0, -40.0, 0.25, 1.0)
    assert failed <= -13.1 < passed and passed - failed <= 0.25 and trials[3] == (-15.0, False)
    # whole numbers (a delay in physics steps): exact, 1, 3, 7, 15, 31 steps out
    passed, failed, trials = find_threshold(lambda n: n <= 17, 0, 50, 1.0, 1, integer=True)
    assert (passed, failed) == (17, 18) and all(float(v).is_integer() for v, _ in trials)
    assert find_threshold(lambda n: n < 1, 0, 50, 1.0, 1, integer=True) == (0.0, 1.0, [(1.0, False)])
    # nothing fails in the range: the last step is the limit, no failure found
    passed, failed, trials = find_threshold(lambda x: True, 0.0, 20.0, 0.25, 1.0)
    assert (passed, failed) == (20.0, None) and trials[-1] == (20.0, True) and len(trials) == 5
    passed, failed, _ = find_threshold(lambda x: x < 20.0, 0.0, 20.0, 0.25, 1.0)
    assert failed == 20.0 and 20.0 - passed <= 0.25
    # a pass region beyond the first failure is not reached (searched outwards from the nominal)
    passed, failed, _ = find_threshold(lambda x: x < 2.0 or x > 10.0, 0.0, 20.0, 0.25, 1.0)
    assert passed < 2.0 <= failed


def test_bound_and_verdict():
    nominal = {"failed": False, "failure_reason": "", "rate_error_rad": 1.5, "gimbal_rate_limit_s": 0.2,
               "duration_s": 70.0}
    b = bounds(nominal, MarginOptions(error_ratio=2.0, rate_limit_ratio=3.0))
    assert b == {"rate_error_rad": 3.0, "gimbal_rate_limit_s": 3.0 * RATE_LIMIT_FLOOR_S}
    calm = bounds({**nominal, "rate_error_rad": 0.003, "gimbal_rate_limit_s": 4.0}, MarginOptions())
    assert calm == {"rate_error_rad": pytest.approx(2.0 * RATE_ERROR_FLOOR_RADPS * 70.0), "gimbal_rate_limit_s": 8.0}
    assert verdict({**nominal, "rate_error_rad": 2.9}, b) == ""
    assert verdict({**nominal, "rate_error_rad": 3.1}, b) == "rate error"
    assert verdict({**nominal, "gimbal_rate_limit_s": 3.5}, b) == "rate limit"
    assert verdict({**nominal, "failed": True, "failure_reason": "q-alpha"}, b) == "failure: q-alpha"
    assert bounds(nominal, MarginOptions(rate_limit_ratio=math.inf))["gimbal_rate_limit_s"] == math.inf
    with pytest.raises(ValueError, match="error_ratio"):
        MarginOptions(error_ratio=1.0)


def test_summary_takes_the_worst_seed_and_counts():
    seeds = [{"seed": 1, "passed": 6.0, "failed_at": 6.2, "trials": [1] * 7},
             {"seed": 2, "passed": 4.5, "failed_at": 4.7, "trials": [1] * 7},
             {"seed": 3, "passed": 20.0, "failed_at": None, "trials": [1] * 8},
             {"seed": 4, "passed": None, "failed_at": None, "trials": []}]
    s = _summary(seeds, 20.0)
    assert (s["margin"], s["failed_at"], s["worst_seed"], s["median"]) == (4.5, 4.7, 2, 6.0)
    assert s["bracket_width"] == pytest.approx(0.2)
    assert (s["n_seeds"], s["n_nominal_failed"], s["n_bracketed"], s["episodes"]) == (4, 1, 2, 22)
    down = _summary([{"seed": 1, "passed": -12.0, "failed_at": -12.25, "trials": []},
                     {"seed": 2, "passed": -8.0, "failed_at": -8.25, "trials": []}], -40.0)
    assert down["margin"] == -8.0                              # the smallest reduction is the margin
    none = _summary([{"seed": 1, "passed": None, "failed_at": None, "trials": []}], 20.0)
    assert none["margin"] is None and none["n_nominal_failed"] == 1


@pytest.fixture(scope="module")
def short_rigid():
    return next(c for c in get_suite("smile-v1").with_options(mission_time_s=SHORT).conditions if c.model == "rigid")


def test_end_to_end_pid_margins_are_finite_and_seeded(short_rigid):
    opts = MarginOptions(gain_tol_db=1.0, delay_max_s=0.2)
    r = time_domain_margins(POLICIES["pid"], short_rigid, [10000], options=opts, executor="serial")
    c = r["conditions"][short_rigid.name]
    assert c["delay_resolution_ms"] == pytest.approx(10.0) and r["seeds"] == [10000] and r["seed_set"] == "test"
    logged = ledger.read()[-1]                                   # a test seed: the call is in the ledger
    assert (logged["command"], logged["policies"], logged["seeds"]) == ("margins", ["pid"], [[10000, 10000]])
    up, delay = c["gain_up_dB"], c["delay_ms"]
    assert 0.0 < up["margin"] < up["failed_at"] <= 20.0 and up["bracket_width"] <= 1.0
    assert 0.0 < delay["margin"] < delay["failed_at"] <= 200.0 and delay["bracket_width"] == pytest.approx(10.0)
    assert c["gain_down_dB"]["n_seeds"] == 1 and not c["nominal"][0]["failed"]
    again = time_domain_margins(POLICIES["pid"], short_rigid, [10000], options=opts, experiments=["delay"],
                                executor="serial")
    assert again["conditions"][short_rigid.name]["delay_ms"] == delay
    table = margins_table([r])
    assert "| pid | smile-v1/rigid |" in table and "10 ms (the physics step)" in table


def test_the_batched_searches_fly_the_single_env_episodes(short_rigid):
    """Each round of the searches flies its trials as rows of one batched flight, with per-row gains and
    delays: every trial's record is the single env's episode with that gain or delay (perturb.fly)."""
    from lvgym.benchmark.margins import MarginTask, run_margin_task
    from lvgym.benchmark.perturb import fly

    opts = MarginOptions(gain_tol_db=2.0, delay_max_s=0.1)
    specs = (POLICIES["pid"], POLICIES["lqg"])
    results = run_margin_task(MarginTask(specs, short_rigid, (10000, 10001), EXPERIMENTS, opts))
    assert len(results) == 2 * 2 * len(EXPERIMENTS)
    checked = 0
    for r in results:
        spec = POLICIES[r["policy"]]
        assert fly(spec, short_rigid, r["seed"]) == r["nominal"]
        for trial in r["trials"]:
            gain = db_to_gain(trial["value"]) if r["experiment"] != "delay" else 1.0
            delay = int(round(trial["value"] / (1e3 * r["physics_dt_s"]))) if r["experiment"] == "delay" else 0
            single = fly(spec, short_rigid, r["seed"], gain, delay)
            assert {k: trial[k] for k in single} == single, (r["policy"], r["experiment"], trial["value"])
            checked += 1
    assert checked > len(results)


def test_cli_refuses_bad_values_and_writes_its_files(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["--gain-tol-db", "-1", "--no-progress"])
    assert "--gain-tol-db = -1" in capsys.readouterr().err
    with pytest.raises(SystemExit, match="whole multiple"):
        main(["--physics-dt-s", "0.003", "--no-progress"])
    out = tmp_path / "m"
    main(["--policies", "pid", "--models", "rigid", "--seeds", "1", "--experiments", "delay", "--delay-max-s",
          "0.05", "--mission-time-s", str(SHORT), "--executor", "serial", "--out", str(out), "--no-progress"])
    assert "| pid | smile-v1/rigid |" in capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == ["margin_trials.csv", "margins.csv", "margins.json", "margins.md"]
    data = json.loads((out / "margins.json").read_text())
    assert data["meta"]["version"].endswith("+override") and data["results"][0]["experiments"] == ["delay"]
    assert data["results"][0]["seeds"] == [0] and data["results"][0]["seed_set"] == "validation"    # the default
    before = len(ledger.read())
    main(["--policies", "pid", "--models", "rigid", "--seeds", "1", "--experiments", "delay", "--delay-max-s",
          "0.02", "--mission-time-s", str(SHORT), "--executor", "serial", "--out", str(out), "--no-progress",
          "--seed-set", "test", "--purpose", "a deliberate check"])
    assert "lvgym margins: flying 1 test seeds (10,000-10,000) on purpose" in capsys.readouterr().err
    assert len(ledger.read()) == before + 1 and ledger.read()[-1]["purpose"] == "a deliberate check"

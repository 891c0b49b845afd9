"""The tables of docs/rl.md, docs/benchmark.md and docs/test-seeds.md, generated from the code: the layouts of
``lvgym/envs/layouts.py``, the option groups of ``lvgym/envs/options.py`` (their field docstrings and
ranges), the protocol presets of ``lvgym/envs/presets.py`` and the dispersion table of
``lvgym/envs/dispersions.py``; and how often each policy of protocol v2 has flown on test seeds, from the
ledger of test flights (``docs/data/test-flights.jsonl``).

    python docs/gen_tables.py            # rewrite the generated blocks of the pages
    python docs/gen_tables.py --check    # exit 1 (and say which blocks) if a page is not what the code gives

A generated block sits between ``<!-- generated: NAME -->`` and ``<!-- end: NAME -->``. The page in the
repository holds the tables (readable without building the site), ``tests/test_docs_site.py`` checks that
they are what the layouts give, and this module is also an mkdocs hook (``mkdocs.yml``, ``hooks:``): the
site renders the blocks from the layouts at build time. The ``info`` keys are not a layout: their table is
:data:`INFO` below, and the test compares its keys with a flown env's ``info``.
"""

from __future__ import annotations

import dataclasses
import re
import sys
from pathlib import Path
from typing import Any, Callable

PAGE = Path(__file__).resolve().parent / "rl.md"
#: the pages with generated blocks, and their blocks
PAGES = {PAGE: ("options", "presets", "observation", "action", "reward", "termination", "info"),
         PAGE.parent / "benchmark.md": ("dispersions", "faults"),
         PAGE.parent / "test-seeds.md": ("test_flights",)}

#: the keys of a step's ``info`` (``AscentFuncEnv.transition_info``): unit and meaning. After a reset the
#: ``info`` holds ``time``, ``cumulative_rate_error``, ``mass`` and ``controller_on`` only.
INFO = {
    "reward_terms": ("-", "the named reward terms of the step (table above); they add up to the reward"),
    "cumulative_rate_error": ("rad", "integral of abs(rate - reference) since the reset (roll, pitch, yaw)"),
    "rate_error": ("rad/s", "abs(rate - reference) after the step (roll, pitch, yaw)"),
    "qbar": ("Pa", "dynamic pressure"),
    "mach": ("-", "Mach number"),
    "alpha_total": ("rad", "total angle of attack"),
    "qalpha_pa_deg": ("Pa deg", "dynamic pressure times total angle of attack (the structural load measure)"),
    "qalpha_limit_pa_deg": ("Pa deg", "the structural limit of `qalpha_pa_deg` at this step: the option "
                                      "`qalpha_limit_pa_deg`, or the vehicle file's `qalpha_limit` over Mach or time "
                                      "([vehicle files](vehicles.md))"),
    "time": ("s", "flight time"),
    "stage": ("-", "index of the lowest attached stage"),
    "controller_on": ("-", "whether the controller acted in the step (off before `controller_on_after_s` "
                           "and while no engine burns)"),
    "slosh_angles": ("rad", "each pendulum's deflection from the body axis in the x-y and x-z body planes (0 at rest, "
                             "hanging aft); NaN for a pendulum without mass"),
    "eta": ("sqrt(kg) m", "modal coordinates: the K modes of the y plane, then z"),
    "gimbal": ("rad", "gimbal angles (pitch, yaw)"),
    "gimbal_rate": ("rad/s", "gimbal rates (pitch, yaw)"),
    "effort_rad_s": ("rad s", "integral of abs(gimbal pitch) + abs(gimbal yaw) over the control period"),
    "attitude_error": ("rad", "attitude error (pitch, yaw) against the reference axis"),
    "mass": ("kg", "vehicle mass"),
    "termination": ("-", "why the episode ended (the termination table), empty while it flies"),
    "events": ("-", "the events of the step (burnout, separation, ignition, lift-off, rail exit): a list of "
                    "(time [s], text); in a batched info, a tuple per row"),
    "fault": ("-", "only when `randomize` holds `fault`: at the step that ends the episode, the in-flight fault it "
                   "flew (e.g. `stuck pitch`); empty at every other step ([benchmark](benchmark.md), \"In-flight "
                   "faults\")"),
}


def _markdown(doc: str) -> str:
    """A docstring's reStructuredText as Markdown: ``code`` and :role:`~a.b.name` become code spans."""
    doc = re.sub(r":\w+:`~[\w.]*?(\w+)`", r"`\1`", doc)
    doc = re.sub(r":\w+:`\.*([\w.]+)`", r"`\1`", doc)
    return doc.replace("``", "`")


def _cell(text: str) -> str:
    """A Markdown table cell: pipes and emphasis characters escaped."""
    return text.replace("|", "\\|").replace("*", "\\*")


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(_cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def observation() -> str:
    """The observation of the three modes (``state``, ``sensors``, ``flight``), entry by entry."""
    from lvgym.envs.layouts import FLIGHT_SOURCE, OBS_FLIGHT, OBS_SENSORS, OBS_STATE

    rows = []
    for (o, f), (_, g), (_, h) in zip(OBS_STATE.leaves(), OBS_SENSORS.leaves(), OBS_FLIGHT.leaves()):
        same = f.name == g.name == h.name and f.doc == g.doc == h.doc
        name = f"`{f.name}`" if f.name == g.name else f"`{f.name}` / `{g.name}`"
        unit = f.unit if f.unit == g.unit else f"{f.unit} / {g.unit}"
        meaning = f.doc if same else f"state: {f.doc}; sensors: {g.doc}; flight: {h.doc}"
        source = FLIGHT_SOURCE[g.name] if same else f"state: none (ideal); sensors, flight: {FLIGHT_SOURCE[g.name]}"
        rows.append([str(o), name, unit, meaning, source])
    return _table(["index", "name (state / sensors, flight)", "unit", "meaning", "flight computer source"], rows)


def action() -> str:
    """The action of each ``control`` (as the observation history records it)."""
    from lvgym.envs.layouts import ACTIONS

    space = {"tvc": "`Box(-1, 1, (2,))`", "rcs": "`MultiDiscrete([3])`"}
    rows = [[f"`{control}`", space[control], str(o), f"`{f.name}`", f.unit, f.doc]
            for control, layout in ACTIONS.items() for o, f in layout.leaves()]
    return _table(["control", "space", "index", "name", "unit", "meaning"], rows)


def reward() -> str:
    """The reward terms (``info["reward_terms"]``), in the compiled kernel's order."""
    from lvgym.envs.layouts import REWARD

    return _table(["term", "unit", "meaning"], [[f"`{f.name}`", f.unit, f.doc] for _, f in REWARD.leaves()])


def termination() -> str:
    """The termination codes and the truncation."""
    from lvgym.envs.layouts import REASONS

    rows = [[str(code), f"`{reason}`", "terminated"] if reason else
            [str(code), '`""`', "not terminated; truncated when the mission time (`mission_time_s`) is flown"]
            for code, reason in enumerate(REASONS)]
    return _table(["code", "`info[\"termination\"]`", "ends the episode as"], rows)


def info() -> str:
    """The keys of a step's ``info``."""
    return _table(["key", "unit", "meaning"], [[f"`{key}`", unit, doc] for key, (unit, doc) in INFO.items()])


def _shown(value: Any) -> str:
    """A default or preset value as the tables show it."""
    if isinstance(value, frozenset):
        return "{" + ", ".join(sorted(value)) + "}" if value else "{}"
    if hasattr(value, "__dataclass_fields__"):                          # a SlenderGeometry
        return ", ".join(f"{k} {getattr(value, k)}" for k in value.__dataclass_fields__)
    return repr(value) if isinstance(value, str) else str(value)


def options() -> str:
    """Every option of a task, group by group: its keyword, default, what is allowed and its docstring."""
    from lvgym.cli.args import field_docs
    from lvgym.envs.options import rule_of
    from lvgym.envs.spec import GROUPS, TaskSpec

    top = field_docs(TaskSpec)
    rows = [["", "`vehicle`", "(the env's)", "a shipped name, a YAML path or a `SlenderGeometry`",
             _markdown(top["vehicle"])],
            ["", "`model`", "`'nonrigid'`", "`rigid`, `slosh`, `flex`, `nonrigid`", _markdown(top["model"])]]
    for group, cls in GROUPS.items():
        docs = field_docs(cls)
        for f in dataclasses.fields(cls):
            rule = rule_of(f)
            allowed = rule.allowed() if rule else "see the meaning"
            rows.append([f"`{group}`", f"`{f.name}`", f"`{_shown(f.default)}`", allowed,
                         _markdown(docs[f.name])])
    return _table(["group", "keyword", "default", "allowed", "meaning"], rows)


def presets() -> str:
    """The protocol presets of the env ids: every option a preset sets away from the defaults."""
    from lvgym import ENV_IDS, env_class
    from lvgym.envs.spec import TaskSpec

    specs = {env_id: env_class(env_id).PRESET for env_id in ENV_IDS}
    base = {env_id: TaskSpec(spec.vehicle).options() for env_id, spec in specs.items()}
    keys = [k for k in next(iter(specs.values())).options()
            if k == "vehicle" or any(spec.options()[k] != base[i][k] for i, spec in specs.items())]
    rows = [[f"`{k}`"] + [_shown(spec.options()[k]) if k == "vehicle" or spec.options()[k] != base[i][k] else ""
                          for i, spec in specs.items()] for k in keys]
    return _table(["keyword"] + [f"`{i.removeprefix('lvgym/')}`" for i in specs], rows)


def dispersions() -> str:
    """The dispersions, row by row in the order a reset draws them (lvgym.envs.dispersions.DISPERSIONS)."""
    from lvgym.envs.dispersions import DISPERSIONS, OTHER_RANDOMIZATIONS, RANDOMIZE_V0

    rows = [[f"`{d.name}`" + (" (v0)" if d.name in RANDOMIZE_V0 else ""), d.what, d.law_text(), d.clip_text(), d.source]
            for d in DISPERSIONS]
    rows += [[f"`{name}`" + (" (v0)" if name in RANDOMIZE_V0 else ""), text.split(": ")[0], "", "", text.split(": ")[1]]
             for name, text in OTHER_RANDOMIZATIONS.items()]
    return _table(["name", "what is drawn", "law", "clip", "why this range"], rows)


def faults() -> str:
    """The kinds of in-flight fault (lvgym.envs.faults.FAULT_KINDS)."""
    from lvgym.envs.faults import FAULT_KINDS

    rows = [[f"`{k.name}`", k.what, "-" if k.high == k.low == 0.0 else
             (f"{k.low * 100:g}-{k.high * 100:g} %" if k.unit == "-" else f"{k.low:g}-{k.high:g} {k.unit}"),
             "pitch or yaw" if k.one_axis else "-", k.source] for k in FAULT_KINDS]
    return _table(["kind", "what", "size", "axis", "why this range"], rows)


def test_flights() -> str:
    """How often each policy protocol v2 reports has flown on test seeds: the committed ledger of test flights
    (``docs/data/test-flights.jsonl``; ``lvgym ledger --headline``)."""
    from lvgym.benchmark.ledger import LEDGER_IN_REPO, read, table
    from lvgym.benchmark.suites import SUITES_V2

    names = list(dict.fromkeys(p for s in SUITES_V2.values() for p in s.policies))
    return table(read(PAGE.parent.parent / LEDGER_IN_REPO), names).rstrip("\n")


BLOCKS: dict[str, Callable[[], str]] = {"options": options, "presets": presets, "observation": observation,
                                        "action": action, "reward": reward, "termination": termination, "info": info,
                                        "dispersions": dispersions, "faults": faults, "test_flights": test_flights}
_BLOCK = re.compile(r"(<!-- generated: (\w+) -->\n)(.*?)(<!-- end: \2 -->)", re.S)


def render(markdown: str) -> str:
    """``markdown`` with every generated block filled from the code."""
    def fill(m: re.Match) -> str:
        if m.group(2) not in BLOCKS:
            raise KeyError(f"generated block {m.group(2)!r}: unknown; known: {sorted(BLOCKS)}")
        return f"{m.group(1)}{BLOCKS[m.group(2)]()}\n{m.group(4)}"
    return _BLOCK.sub(fill, markdown)


def stale(markdown: str) -> list[str]:
    """The names of the blocks of ``markdown`` that differ from what the layouts give."""
    fresh = {m.group(2): m.group(3) for m in _BLOCK.finditer(render(markdown))}
    return [m.group(2) for m in _BLOCK.finditer(markdown) if m.group(3) != fresh[m.group(2)]]


def on_page_markdown(markdown: str, page: Any, **kwargs: Any) -> str:
    """mkdocs hook: the generated blocks of the page, from the code."""
    return render(markdown) if _BLOCK.search(markdown) else markdown


def main(argv: list[str]) -> int:
    status = 0
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        if "--check" in argv:
            old = stale(text)
            if old:
                print(f"docs/{page.name}: generated blocks out of date: {', '.join(old)} (run python docs/gen_tables.py)")
                status = 1
        else:
            page.write_text(render(text), encoding="utf-8")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""The docs site builds in strict mode (no broken link or anchor, every page in the nav, a clean API
reference), its generated tables are what the layouts give, the install page lists every dependency, and
no tracked file cites the design notes and reference files that a clone does not have."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
_SPEC = importlib.util.spec_from_file_location("gen_tables", DOCS / "gen_tables.py")
gen_tables = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(gen_tables)


def test_mkdocs_build_strict(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings_handlers.python")
    site = tmp_path / "site"
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                          cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    rl = (site / "rl" / "index.html").read_text(encoding="utf-8")
    assert "pitch_rate_error" in rl and "q-alpha beyond the structural limit" in rl     # the generated tables
    agents = (site / "api" / "agents" / "index.html").read_text(encoding="utf-8")
    assert 'id="lvgym.agents.policies.sb3.SB3Policy"' in agents    # agents/ documented as lvgym.agents
    assert ":class:" not in agents                                  # Sphinx roles became code spans


def _nav_pages(items) -> list[str]:
    out = []
    for item in items:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        out += _nav_pages(value) if isinstance(value, list) else [value]
    return out


def test_every_page_in_the_nav():
    nav = _nav_pages(yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))["nav"])
    pages = sorted(str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md"))
    assert sorted(nav) == pages


def test_generated_tables_are_the_code():
    assert sorted(b for blocks in gen_tables.PAGES.values() for b in blocks) == sorted(gen_tables.BLOCKS)
    for page, blocks in gen_tables.PAGES.items():
        text = page.read_text(encoding="utf-8")
        assert re.findall(r"<!-- generated: (\w+) -->", text) == list(blocks), page.name
        assert gen_tables.stale(text) == [], f"{page.name}: run python docs/gen_tables.py"
    assert gen_tables.main(["--check"]) == 0


def test_rl_tables_follow_a_changed_layout():
    """A stale block is found, and rendering fills it."""
    text = gen_tables.PAGE.read_text(encoding="utf-8").replace("| `rate_pitch` |", "| `rate_pitch_old` |")
    assert gen_tables.stale(text) == ["reward"]
    assert gen_tables.stale(gen_tables.render(text)) == []


def test_info_table_is_the_envs_info():
    import gymnasium as gym

    import lvgym  # noqa: F401

    env = gym.make("lvgym/SmileAscent-v1", mission_time_s=1.0)
    _, reset_info = env.reset(seed=0)
    _, _, _, _, info = env.step(env.action_space.sample())
    assert list(info) == [k for k in gen_tables.INFO if k != "fault"]
    assert set(reset_info) == {"time", "cumulative_rate_error", "mass", "controller_on"}
    faulty = gym.make("lvgym/SmileAscent-v1", mission_time_s=1.0, randomize={"fault"})     # the key of faults
    faulty.reset(seed=0)
    assert list(faulty.step(faulty.action_space.sample())[4]) == list(gen_tables.INFO)


def _requirement_names(reqs: list[str]) -> set[str]:
    return {re.split(r"[<>=!~\[; ]", r, maxsplit=1)[0].lower() for r in reqs if not r.startswith("lvgym")}


def test_install_page_lists_every_dependency():
    """docs/install.md's table of why each dependency is there: every requirement of pyproject.toml, and
    nothing else but torch (installed by the Makefile)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    required = _requirement_names(project["dependencies"])
    for extra in project["optional-dependencies"].values():
        required |= _requirement_names(extra)
    text = (DOCS / "install.md").read_text(encoding="utf-8")
    table = text[text.index("## Why each dependency is there"):]
    listed = set(re.findall(r"^\| ([a-z0-9-]+) \|", table, re.M)) - {"package"}
    assert listed == required | {"torch"}


# built from parts so that this file does not name them itself
FORBIDDEN = ["shared/" + "DESIGN", "shared/" + "seed", "shared/" + "reference", "../" + "shared",
             "DESIGN" + ".md", "public-data" + ".md", "thesis-cases" + ".md", "control-practice" + ".md"]


def test_no_file_cites_the_design_notes():
    """The design notes and the reference files were a workplace's, not the repository's: the product
    cites the thesis, the standards and its own docs pages instead."""
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    hits = []
    for name in files.decode().split("\0"):
        path = ROOT / name
        if not name or not path.is_file() or path.suffix in (".png", ".npz", ".zip", ".pkl"):
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        hits += [f"{name}: {word}" for word in FORBIDDEN if word in text]
    assert not hits, hits

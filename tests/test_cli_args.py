"""The dataclass-to-command-line helper (lvgym.commandline) and the console script ``lvgym`` (lvgym.cli.main):
help from the fields' docstrings with the defaults, every supported type, the checks declared on a field
refused in one line before any work, "did you mean" for a mistyped option or command, the subcommands and
their extras; and that every command line of the project is declared with the helper."""

from __future__ import annotations

import ast
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import pytest

from lvgym.commandline import arg, build_parser, check_fields, Command, command_name, dispatch, parse, parse_given
from lvgym.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]


def _even(option: str, value: int) -> int:
    if value % 2:
        raise ConfigError(option, value, "an even number")
    return value


@dataclass
class Demo:
    """A command line with one field of each kind."""

    name: str = "x"
    """a plain string"""
    count: int = arg(3, lo=1, hi=10)
    """an integer in a range (100 % of it)"""
    ratio: float | None = arg(None, lo=0.0, lo_open=True, hi=1.0)
    """an optional fraction (default: none)"""
    at_least: int = arg(2, lo=2, hi=99, allowed="an integer >= 2")
    """an integer with the refusal's own words"""
    plots: bool = True
    """a switch"""
    mode: Literal["fast", "slow"] = "fast"
    """a literal"""
    executor: str = arg("local", choices=lambda: ("local", "serial"))
    """choices from a function"""
    items: list[str] = arg(default_factory=lambda: ["a"], metavar="ITEM")
    """a list"""
    hp: list[str] = arg(default_factory=list, nargs="*", extend=True)
    """a list a repeated flag adds to"""
    pair: tuple[float, float] | None = arg(None, lo=0.0, hi=5.0, metavar=("LO", "HI"))
    """two numbers"""
    variant: list[tuple[str, str]] = arg(default_factory=list, metavar=("NAME", "ARGS"))
    """pairs, one per flag"""
    even: int = arg(0, check=_even)
    """a custom check"""

    def __post_init__(self) -> None:
        if self.mode == "slow" and self.count > 5:
            raise ConfigError("--count", self.count, "at most 5 with --mode slow")


def _refused(capsys, argv, cls=Demo) -> str:
    with pytest.raises(SystemExit) as exc:
        parse(cls, argv, "demo")
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert err.startswith("demo: error: ") and err.rstrip().endswith("(see demo --help)")
    return err


def test_the_defaults_and_every_type(capsys):
    assert parse(Demo, [], "demo") == Demo()
    a = parse(Demo, ["--name", "y", "--count", "1e1", "--ratio", "0.5", "--no-plots", "--mode", "slow", "--count", "4",
                     "--items", "b", "c", "--hp", "k=1", "--hp", "j=2", "l=3", "--pair", "1", "2.5",
                     "--variant", "v", "--x 1", "--variant", "w", "", "--even", "4"], "demo")
    assert a == Demo(name="y", count=4, ratio=0.5, plots=False, mode="slow", items=["b", "c"], hp=["k=1", "j=2", "l=3"],
                     pair=(1.0, 2.5), variant=[("v", "--x 1"), ("w", "")], even=4)
    assert isinstance(a.count, int) and parse(Demo, ["--count", "1e1"], "demo").count == 10   # a whole float is an int
    assert parse(Demo, ["--plots"], "demo").plots is True


def test_help_comes_from_the_docstrings_with_the_defaults(capsys):
    text = build_parser(Demo, "demo", "First paragraph.\n\nThe rest.", epilog=True).format_help()
    assert text.startswith("usage: demo ") and "First paragraph." in text and text.rstrip().endswith("The rest.")
    flat = " ".join(text.split())
    assert "--count COUNT an integer in a range (100 % of it) (default: 3)" in flat
    assert "--ratio RATIO an optional fraction (default: none)" in flat and "(default: none) (default" not in flat
    assert "--plots, --no-plots a switch (default: --plots)" in flat
    assert "--mode {fast,slow}" in flat and "--executor {local,serial}" in flat
    assert "--items ITEM [ITEM ...] a list (default: a)" in flat and "--pair LO HI two numbers" in flat


@pytest.mark.parametrize("argv, message", [
    (["--count", "0"], "--count = 0: an integer in [1, 10]"),
    (["--count", "2.5"], "--count = 2.5: an integer in [1, 10]"),
    (["--count", "many"], "--count = 'many': an integer in [1, 10]"),
    (["--ratio", "0"], "--ratio = 0.0: a number in (0.0, 1.0]"),
    (["--ratio", "nan"], "--ratio = nan: a number in (0.0, 1.0]"),
    (["--at-least", "1"], "--at-least = 1: an integer >= 2"),
    (["--pair", "1", "6"], "--pair = 6.0: a number in [0.0, 5.0]"),
    (["--even", "3"], "--even = 3: an even number"),
    (["--mode", "slow", "--count", "6"], "--count = 6: at most 5 with --mode slow"),
    (["--mode", "quick"], "argument --mode: invalid choice: 'quick'"),
    (["--executor", "ray"], "argument --executor: invalid choice: 'ray'"),
    (["--cuont", "3"], "unrecognized arguments: --cuont 3; did you mean --count?"),
    (["--no-plts"], "did you mean --no-plots?"),
    (["--pair", "1"], "argument --pair: expected 2 arguments"),
])
def test_a_bad_value_is_one_line_naming_the_option_the_value_and_what_is_allowed(capsys, argv, message):
    assert message in _refused(capsys, argv)


def test_given_names_and_required_options(capsys):
    a, given = parse_given(Demo, ["--count", "4", "--no-plots"], "demo")
    assert given == {"count", "plots"} and a.count == 4

    @dataclass
    class Needs:
        out: str
        """where"""
        rows: list[float] = arg(positional=True, lo=0.0, hi=9.0)
        """the rows"""
        mode: Literal["check", "write"] = arg(switches={"check": "compare", "write": "write it"})

    assert parse(Needs, ["1", "2", "--out", "o", "--write"], "demo") == Needs("o", [1.0, 2.0], "write")
    assert "the following arguments are required: --out" in _refused(capsys, ["1", "--check"], Needs)
    assert "one of the arguments --check --write is required" in _refused(capsys, ["1", "--out", "o"], Needs)
    assert "rows = 10.0: a number in [0.0, 9.0]" in _refused(capsys, ["10", "--out", "o", "--check"], Needs)


def test_fields_are_checked_on_an_instance_built_in_python():
    assert check_fields(Demo(count=5)) == Demo(count=5)
    for kw, key in (({"count": 11}, "--count"), ({"executor": "ray"}, "--executor"), ({"pair": (1.0, 9.0)}, "--pair"),
                    ({"even": 1}, "--even"), ({"mode": "quick"}, "--mode")):
        with pytest.raises(ConfigError) as err:
            check_fields(Demo(**kw))
        assert err.value.key == key


# ------------------------------------------------------------------------------------------ subcommands
def _echo(argv):
    return [command_name("nobody"), *argv]


COMMANDS = (Command("echo", "test_cli_args:_echo", "say what you are called"),
            Command("group", None, "a group", sub=(Command("inner", "test_cli_args:_echo", "inside"),)),
            Command("heavy", "test_cli_args:_echo", "needs a missing package", "heavy",
                    ("no_such_module_for_lvgym_tests",)))


def test_subcommands_run_under_their_name_and_list_one_line_each(capsys):
    assert dispatch(COMMANDS, ["echo", "a", "b"], "tool") == ["tool echo", "a", "b"]
    assert dispatch(COMMANDS, ["group", "inner"], "tool") == ["tool group inner"]
    assert command_name("nobody") == "nobody"                   # the name is the command's while it runs
    assert dispatch(COMMANDS, ["--help"], "tool", "A tool.") == 0
    out = capsys.readouterr().out
    assert "A tool." in out and "  echo " in out and "  group inner " in out and "  group " not in out.replace(
        "group inner", "")


def test_an_unknown_command_or_a_missing_extra_is_one_line(capsys):
    with pytest.raises(SystemExit) as exc:
        dispatch(COMMANDS, ["ecko"], "tool")
    assert exc.value.code == 2 and "tool: error: unknown command 'ecko'; did you mean echo?" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        dispatch(COMMANDS, ["heavy", "--help"], "tool")
    assert exc.value.code == ("tool heavy: needs no_such_module_for_lvgym_tests, which is not installed: "
                              "pip install 'lvgym[heavy]'")


def test_the_console_script_has_every_command_with_its_help(capsys):
    from lvgym.cli.main import COMMANDS as LVGYM, main

    assert tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"] == {"lvgym": "lvgym.cli.main:main"}
    assert main(["--help"]) == 0
    listed = [line.split("  ")[1] for line in capsys.readouterr().out.splitlines() if line.startswith("  ")]
    expected = ["evaluate", "train", "curves", "campaign", "margins", "headline select", "headline fly", "headline page",
                "compare-headline", "ledger", "fingerprint", "verify", "verify rocketpy", "verify rocketpy-timing",
                "bench", "bench-envs", "bench-train", "studies", "render", "export-policy", "dataset", "bc", "design pid", "design pid-flex",
                "design lqg", "design indi", "design pd-relief", "design charts", "design auto", "vehicle beam", "vehicle slender"]
    assert listed == expected
    for name in expected:
        with pytest.raises(SystemExit) as exc:
            main([*name.split(), "--help"])
        assert exc.value.code == 0, name
        assert capsys.readouterr().out.startswith(f"usage: lvgym {name} "), name
    assert {c.name for c in LVGYM} == {n.split()[0] for n in expected}


# ------------------------------------------------------------------------------------------ declared one way
def _imports(path: Path) -> set[str]:
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            out.add(("." * node.level) + node.module)
    return out


def test_every_command_line_is_declared_with_the_helper():
    """No module builds an argparse parser of its own: lvgym.commandline does, from each command's dataclass."""
    files = [p for d in ("lvgym", "agents", "baselines", "experiments") for p in (ROOT / d).rglob("*.py")]
    files += [ROOT / "train.py", ROOT / "evaluate.py"]
    own = sorted(str(p.relative_to(ROOT)) for p in files if "argparse" in _imports(p))
    assert own == ["lvgym/commandline/messages.py", "lvgym/commandline/options.py"]


def test_the_helpers_of_the_lower_layers_import_no_upper_layer():
    """lvgym.commandline (which any layer may use) imports nothing of lvgym but lvgym.errors and its own modules."""
    names = sorted(p.name for p in (ROOT / "lvgym" / "commandline").glob("*.py"))
    assert names == ["__init__.py", "messages.py", "options.py", "subcommands.py"]
    for name in names:
        mods = {m for m in _imports(ROOT / "lvgym" / "commandline" / name) if m.startswith(("lvgym", "."))}
        assert mods <= {"lvgym.errors", ".messages", ".options", ".subcommands"}, (name, mods)

"""A case per option of every command, read from the parser itself (a new option joins the corpus).

Each option gets hostile values (NaN, inf, a negative, text, an overflowing number, an empty
string; for file options a missing folder, a folder, the input itself) on an otherwise valid
command line.  The command must exit 0, 2 (one line, no output written) or 3; never 1.
"""

from __future__ import annotations

import argparse
import io
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest

from planar.cli.main import build_parser, main

ROOT = Path(__file__).resolve().parents[2]
G = ROOT / "gallery"

#: a valid command line for each command; ``{tmp}`` is the test's folder
BASE: dict[str, list[str]] = {
    "demo": ["demo", "-o", "{tmp}/demo"],
    "bench": ["bench", "kinematics", "-n", "200", "--repeats", "1"],
    "chains": ["chains", "Oz"],
    "render": ["render", str(G / "kangaroo-leg.toml"), "-o", "{tmp}/k.gif"],
    "motion": ["motion", str(G / "kangaroo-leg.toml"), "-o", "{tmp}/k.csv"],
    "catalog": ["catalog", "kangaroo", "-o", "{tmp}/c.csv"],
    "gallery": ["gallery", "-o", "{tmp}/g", "--source", "{tmp}/src"],
    "schema": ["schema", "-o", "{tmp}/s.json"],
    "compare": ["compare", str(G / "kangaroo-leg.toml")],
    "export": ["export", str(G / "kangaroo-leg.toml"), "-o", "{tmp}/k.dxf"],
    "toy": ["toy", str(G / "windup-01.toml")],
    "design": ["design", "{tmp}/req.toml", "-o", "{tmp}/toy.toml"],
    "plot": ["plot", str(G / "kangaroo-leg.toml"), "-o", "{tmp}/p.png"],
    "synth path": ["synth", "path", "{tmp}/t.csv", "-o", "{tmp}/s.toml", "--budget", "quick"],
    "synth function": ["synth", "function", "{tmp}/p.csv", "-o", "{tmp}/f.toml"],
    "synth motion": ["synth", "motion", "{tmp}/m.csv", "-o", "{tmp}/m.toml"],
}
NUMBERS = ["nan", "inf", "-inf", "-1", "0", "abc", "1e400", ""]
PATHS = ["", "{tmp}/missing/x", "{tmp}", "{input}"]
#: options whose valid values are words, checked by argparse choices or by their own parser
WORDS = ["", "nonsense", "1e400", "nan"]


def _options() -> list[tuple[str, str, str]]:
    """``(command, option, kind)`` for every option of every command."""
    parser = build_parser()
    out: list[tuple[str, str, str]] = []

    def walk(name: str, p: argparse.ArgumentParser) -> None:
        subs = [a for a in p._actions if isinstance(a, argparse._SubParsersAction)]
        if subs:
            for n, sp in subs[0].choices.items():
                walk(f"{name} {n}".strip(), sp)
            return
        for a in p._actions:
            if not a.option_strings or isinstance(a, (argparse._HelpAction, argparse._StoreTrueAction)):
                continue
            kind = "number" if a.type in (int, float) else ("path" if a.dest in _PATH_DESTS else "word")
            out.append((name, a.option_strings[-1], kind))

    walk("", parser)
    return out


_PATH_DESTS = {"output", "svg", "preview", "bom", "assembly", "kerf_test", "scenes", "source"}
CASES = [
    (cmd, opt, v)
    for cmd, opt, kind in _options()
    for v in {"number": NUMBERS, "path": PATHS, "word": WORDS}[kind]
    if cmd in BASE and not (cmd == "bench" and opt in ("--output", "--scenes"))  # those belong to bench accuracy
]


def _inputs(tmp: Path) -> None:
    (tmp / "req.toml").write_text('[[effector]]\nname = "ear"\nmotion = "Oz"\nrange = 20.0\n')
    (tmp / "t.csv").write_text("x,y\n0,0\n1,0.2\n2,0.1\n2.5,1\n1,1.5\n")
    (tmp / "p.csv").write_text("input,output\n0.3,1.0\n1.1,1.4\n2.0,1.9\n")
    (tmp / "m.csv").write_text("x,y,angle\n0,0,0\n1,0.5,0.3\n2,0.4,0.7\n")
    (tmp / "src").mkdir()


@pytest.mark.slow
@pytest.mark.parametrize("command,option,value", CASES, ids=[f"{c}|{o}|{v}" for c, o, v in CASES])
def test_option_case(tmp_path: Path, command: str, option: str, value: str) -> None:
    _inputs(tmp_path)
    base = [a.replace("{tmp}", str(tmp_path)) for a in BASE[command]]
    first_input = next((a for a in base[1:] if Path(a).is_file()), str(tmp_path / "none"))
    v = value.replace("{tmp}", str(tmp_path)).replace("{input}", first_input)
    argv = list(base)
    if option in argv:  # replace the base's own value
        argv[argv.index(option) + 1] = v
    elif option == "--output" and "-o" in argv:
        argv[argv.index("-o") + 1] = v
    else:
        argv += [option, v]
    before = {p.name for p in tmp_path.iterdir()}
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        rc = main(argv)
    msg = err.getvalue().strip()
    assert rc in (0, 2, 3), f"{argv}: exit {rc}: {msg}"
    if rc == 2:
        assert len(msg.splitlines()) == 1 and msg.startswith("planar: error: "), msg
        assert {p.name for p in tmp_path.iterdir()} == before, f"{argv} wrote on a refusal"


def _unreachable_inputs(tmp: Path) -> None:
    side = [i / 3 for i in range(3)]
    square = [(s, 0.0) for s in side] + [(1.0, s) for s in side] + [(1 - s, 1.0) for s in side] + [(0.0, 1 - s) for s in side]
    (tmp / "square.csv").write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in square))
    (tmp / "eight.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="200" height="100"><path d="M 100 50 C 130 10, 190 10, '
        '190 50 C 190 90, 130 90, 100 50 C 70 10, 10 10, 10 50 C 10 90, 70 90, 100 50 Z"/></svg>'
    )
    (tmp / "pairs.csv").write_text("input,output\n10,60\n40,75\n70,95\n100,110\n")
    (tmp / "poses.csv").write_text("x,y,angle\n0,0,0\n1,0.2,40\n1.5,1,-30\n0.3,1.4,80\n-0.5,0.6,10\n")


#: every synth type on targets it cannot meet: exit 3 with the reason, never an internal error
UNREACHABLE = {
    "fourbar square": ["synth", "path", "{tmp}/square.csv", "--budget", "quick"],
    "fourbar eight": ["synth", "path", "{tmp}/eight.svg", "--points", "15", "--budget", "quick", "--tolerance", "0.01"],
    "stephenson eight": ["synth", "path", "{tmp}/eight.svg", "--points", "25", "--type", "sixbar", "--budget", "quick"],
    "watt square": ["synth", "path", "{tmp}/square.csv", "--type", "sixbar", "--topology", "watt", "--budget", "quick"],
    "function": ["synth", "function", "{tmp}/pairs.csv", "--deg"],
    "motion": ["synth", "motion", "{tmp}/poses.csv", "--deg"],
}


@pytest.mark.slow
@pytest.mark.parametrize("case", list(UNREACHABLE))
def test_unreachable_targets_exit_3_with_the_reason(tmp_path: Path, case: str, monkeypatch, tmp_path_factory) -> None:
    import json

    monkeypatch.setenv("PLANAR_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "atlas-cache"))  # not the user's
    _unreachable_inputs(tmp_path)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in UNREACHABLE[case]] + ["-o", str(tmp_path / "out.toml")]
    for extra in ([], ["--json"]):
        out, err = io.StringIO(), io.StringIO()
        with redirect_stdout(out), redirect_stderr(err):
            rc = main(argv + extra)
        assert rc == 3, f"{argv + extra}: exit {rc}: {err.getvalue()}"
        if extra:
            rep = json.loads(out.getvalue())
            assert rep["ok"] is False and isinstance(rep.get("reason"), str) and rep["reason"], rep
        else:
            assert "check failed" in out.getvalue(), out.getvalue()

"""The console script's entrance: a Ctrl-C while the command line imports exits 130 quietly."""

from __future__ import annotations

import importlib.abc
import subprocess
import sys

import pytest

from planar.cli import entry


class _InterruptOnImport(importlib.abc.MetaPathFinder):
    """Raise KeyboardInterrupt when ``planar.cli.main`` is imported (a Ctrl-C mid-import)."""

    def find_spec(self, name, path=None, target=None):
        if name == "planar.cli.main":
            raise KeyboardInterrupt
        return None


def test_ctrl_c_while_importing_exits_130(monkeypatch, capsys):
    monkeypatch.delitem(sys.modules, "planar.cli.main", raising=False)
    monkeypatch.setattr(sys, "meta_path", [_InterruptOnImport(), *sys.meta_path])
    with pytest.raises(SystemExit) as exc:
        entry.run()
    assert exc.value.code == 130
    err = capsys.readouterr().err
    assert err.strip() == "planar: interrupted (no output written)"


def test_runs_the_command_and_returns_its_status(monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", ["planar", "schema", "--no-such-option"])
    with pytest.raises(SystemExit) as exc:
        entry.run()
    assert exc.value.code == 2
    assert "Traceback" not in capsys.readouterr().err


def test_console_script_points_at_the_entrance():
    import tomllib
    from pathlib import Path

    project = tomllib.loads((Path(__file__).parents[2] / "pyproject.toml").read_text())
    assert project["project"]["scripts"]["planar"] == "planar.cli.entry:run"


def test_python_dash_m_uses_it():
    out = subprocess.run([sys.executable, "-m", "planar", "--version"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr

"""The README's promises: its Python examples run as written (in a fresh process, from the
repository), its first two commands are the two set-up commands, and it stays a screen or two."""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _blocks(lang):
    return re.findall(rf"```{lang}\n(.*?)```", README, flags=re.S)


def test_the_python_examples_run_as_written(tmp_path):
    blocks = _blocks("python")
    assert blocks, "the README has no Python example"
    code = "\n".join(blocks)
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin",
                                          "MPLBACKEND": "Agg", "HOME": str(tmp_path)})
    assert proc.returncode == 0, proc.stderr[-3000:]


def test_the_examples_comments_state_what_the_code_returns():
    # the quickstart's claims, checked against the library
    import rockjit
    from rockjit import Block, Harmonic
    res = rockjit.simulate(Block(hb=1, law="housner"), Harmonic(alpha=0.6, omega=1.3),
                           lyapunov=True)
    assert rockjit.classify_result(res) == ("symmetric", 1)
    assert "('symmetric', 1)" in README
    assert abs(res.lyapunov[0] + 0.57) < 0.01 and abs(res.lyapunov[1] + 0.57) < 0.01
    quoted = re.search(r"`Block\(hb=0.5\)` says\s+`([^`]+)`", README).group(1)
    try:
        Block(hb=0.5)
    except ValueError as exc:
        assert str(exc).startswith(" ".join(quoted.split())), (str(exc), quoted)
    else:
        raise AssertionError("Block(hb=0.5) was accepted")


def test_it_opens_with_the_two_set_up_commands():
    first = _blocks("bash")[0].strip().splitlines()
    assert first[0].startswith('pip install -e . && rockjit paper --out paper')
    assert first[1].startswith('pip install -e ".[test]" && python -m pytest')
    assert README.index("```bash") < README.index("## ")


def test_it_stays_short_and_points_inside_the_repository():
    assert len(README.splitlines()) <= 150
    for target in re.findall(r"\]\(([^)#]+)\)", README):
        if not target.startswith("http"):
            assert (ROOT / target).exists(), target


def test_one_version_everywhere():
    # pyproject reads the version from rockjit/__init__.py; the citation metadata and the
    # installed package's metadata say the same
    import importlib.metadata
    import tomllib

    import rockjit
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "rockjit.__version__"}
    cff = re.search(r"^version:\s*(\S+)\s*$", (ROOT / "CITATION.cff").read_text(), re.M)
    assert cff and cff.group(1).strip("\"'") == rockjit.__version__
    assert importlib.metadata.version("rockjit") == rockjit.__version__

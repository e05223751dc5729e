"""The README's promises: its Python examples run as written (in a fresh process, from the
repository) and print what they compute, its first two commands are the two set-up commands,
it stays a screen or two, and every number it quotes from rockjit's results is what rockjit
computes today (each recomputed here, at the README's settings, and compared with the text)."""

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
    # run as a script, the quickstart shows every result it makes, each in a few lines
    printed = proc.stdout.splitlines()
    assert len(re.findall(r"^print\(", code, flags=re.M)) >= 6
    assert "('symmetric', 1)" in proc.stdout and "<rockjit.SweepResult: 501 amplitudes>" in printed
    assert any(ln.startswith("<rockjit.BasinResult: 100×100") for ln in printed)
    assert any(ln.startswith("<rockjit.ErosionResult: 36 amplitudes") for ln in printed)
    assert "'overturn'" in printed[-1]
    assert len(printed) <= 60, proc.stdout


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

    import pytest

    import rockjit
    tomllib = pytest.importorskip("tomllib" if sys.version_info >= (3, 11) else "tomli")
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"] and "version" in project["project"]["dynamic"]
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "rockjit.__version__"}
    cff = re.search(r"^version:\s*(\S+)\s*$", (ROOT / "CITATION.cff").read_text(), re.M)
    assert cff and cff.group(1).strip("\"'") == rockjit.__version__
    assert importlib.metadata.version("rockjit") == rockjit.__version__


def _number(pattern):
    m = re.search(pattern, " ".join(README.split()))
    assert m, pattern
    return m


def test_the_multiperiodic_examples_fate_is_todays():
    import rockjit
    from rockjit import Block, Harmonic
    m = _number(r"of (\d+) runs within \$10\^\{-10\}\$ of its initial state, (\d+) % overturn "
                r"and (\d+) % settle on a period-(\d+) orbit")
    n, over, other, period = (int(v) for v in m.groups())
    f = rockjit.fate(Block(hb=1), Harmonic(alpha=0.969, omega=1.3), ensemble=n)
    assert f.settings["spread"][1] == 1e-10
    assert round(100 * f.probabilities["overturn"]) == over
    assert round(100 * f.probabilities[f"multiperiodic p={period}"]) == other
    assert "64 runs within 1e-10 of z0" in README  # the quickstart's call: the default ensemble
    assert f.settings["ensemble"] == rockjit.fate.plan(
        Block(hb=1), Harmonic(alpha=0.969, omega=1.3)).ensemble


def test_the_integrity_of_both_laws_is_as_quoted():
    import numpy as np

    import rockjit
    from rockjit import Block, Harmonic
    m = _number(r"global integrity \(GIM\) is ([\d.]+) of Housner's at \$\\alpha = ([\d.]+)\$ and "
                r"([\d.]+) of it at \$\\alpha = ([\d.]+)\$, while its integrity factor \(IF\) "
                r"stays within ([\d.]+) of Housner's up to \$\\alpha = ([\d.]+)\$ and falls to "
                r"([\d.]+)–([\d.]+) of it from \$\\alpha = ([\d.]+)\$ to \$([\d.]+)\$ "
                r"\((\d+) × \d+ basins, (\d+) periods\)")
    r_lo, a_lo, r_hi, a_hi, tol, a_same, if_lo, if_hi, a_half, a_end, grid, periods = \
        m.groups()
    step = 0.1
    alphas = np.round(np.arange(float(a_lo), float(a_end) + step / 2, step), 10)
    assert float(a_hi) in alphas and float(a_same) in alphas and float(a_half) in alphas
    prof = {law: rockjit.erosion(Block(hb=1, law=law), Harmonic(omega=1.3), alphas, int(grid),
                                 integration=rockjit.Integration(periods=int(periods)))
            for law in ("housner", "mao")}
    gim = prof["mao"].GIM / prof["housner"].GIM
    assert f"{gim[alphas == float(a_lo)][0]:.2f}" == r_lo
    assert f"{gim[alphas == float(a_hi)][0]:.2f}" == r_hi
    same = alphas <= float(a_same) + 1e-9
    assert np.all(np.abs(prof["mao"].IF - prof["housner"].IF)[same] <= float(tol))
    late = alphas >= float(a_half) - 1e-9
    ratio = prof["mao"].IF[late] / prof["housner"].IF[late]
    assert (f"{ratio.min():.2f}", f"{ratio.max():.2f}") == (if_lo, if_hi)


def test_maos_overturning_onset_is_as_quoted():
    import numpy as np

    import rockjit
    from rockjit import Block, Harmonic
    onset = float(_number(r"overturns at every amplitude from α = ([\d.]+)").group(1))
    sw = rockjit.sweep(Block(hb=1, law="mao"), Harmonic(omega=1.3),
                       rockjit.alpha_grid((0.5, 1.0), 0.001))
    over = sw.names[sw.label] == "overturn"
    first = np.flatnonzero(~over)[-1] + 1  # every amplitude from here on overturns
    assert round(float(sw.alpha[first]), 3) == onset

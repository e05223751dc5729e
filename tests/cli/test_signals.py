"""One outcome per run: the exit status of a command says whether ``--out`` was published.

Each run is a real process (the console script's entry point ``rockjit.cli.main``, or ``python -m
rockjit``) sent SIGINT or SIGTERM at a known moment: the process is started by a few lines of
this file (:data:`PAUSING`) that wrap one step of the run so that it stops there (``rockjit:
paused at <point>`` on stderr) until a signal arrives: the import of the commands (``imports``),
the summary written after the work (``work``), the publication of ``--out`` (``published``) or
the command's last line (``wrote``). Before publication a signal leaves ``--out`` as it was and
exits 130 (SIGINT) or 143 (SIGTERM); after it, the run has succeeded (exit status 0, and it says
so), and its chunks are cleaned up all the same. Never a traceback.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = "import sys, rockjit.cli; sys.exit(rockjit.cli.main())"  # as the console script
#: The console script (or ``python -m rockjit``: ``sys.argv[1] == "-m"``) with one step wrapped
#: to pause at ``sys.argv[1]`` until the command's handler has recorded a signal (at most 60 s);
#: the handler's state is the one it is marked with (``rockjit_state``, rockjit.cli.signals)
PAUSING = """
import runpy, signal, sys, time

import rockjit.cli

entry = rockjit.cli.main  # (importing rockjit.cli.main below rebinds the name to the module)
point = sys.argv.pop(1)
how = sys.argv.pop(1)


def pause():
    state = signal.getsignal(signal.SIGINT).rockjit_state
    n = len(state.received)
    print(f"rockjit: paused at {point}", file=sys.stderr, flush=True)
    deadline = time.monotonic() + 60.0
    while len(state.received) == n and time.monotonic() < deadline:
        time.sleep(0.01)


def after(module, name):
    real = getattr(module, name)

    def wrapped(*args, **kwargs):
        value = real(*args, **kwargs)
        pause()
        return value
    setattr(module, name, wrapped)


class PauseAtTheImport:  # the import of the commands, after the handler is installed
    def find_spec(self, name, path=None, target=None):
        if name == "rockjit.cli.main":
            sys.meta_path.remove(self)
            pause()
        return None


if point == "imports":
    sys.meta_path.insert(0, PauseAtTheImport())
elif point == "work":
    from rockjit import outputs
    after(outputs, "summary")
elif point == "published":
    from rockjit.storage.output_dir import OutputDir
    after(OutputDir, "publish")
elif point == "wrote":
    import importlib
    commands = importlib.import_module("rockjit.cli.main")

    def say(args, message, real=commands.say):
        real(args, message)
        if message.startswith(f"{args.command}: wrote"):
            pause()
    commands.say = say
if how == "script":
    sys.exit(entry())
sys.argv[0] = "rockjit"
runpy.run_module("rockjit", run_name="__main__", alter_sys=True)
"""
BASIN = ["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3", "--grid", "6", "--periods",
         "20", "--n-steps", "64"]
COR = ["cor", "--quiet"]
SIGNALS = {"SIGINT": (signal.SIGINT, 130), "SIGTERM": (signal.SIGTERM, 143)}


def _default_sigint():
    # a shell that starts the tests in the background (`cmd &`) has them ignore SIGINT, and
    # the child would inherit that until rockjit installs its handler
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(argv, cwd, pause, how="script"):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    head = [sys.executable, "-c", PAUSING, pause, "script" if how == "script" else "-m"]
    return subprocess.Popen(head + argv, cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_default_sigint)


def _until_paused(proc, point):
    """The stderr lines up to ``rockjit: paused at <point>``."""
    lines = []
    while True:
        line = proc.stderr.readline()
        if not line:
            proc.kill()
            out, err = proc.communicate(timeout=60)
            pytest.fail(f"exited ({proc.returncode}) without pausing at {point}:\n"
                        f"{''.join(lines)}{err}")
        lines.append(line)
        if line.strip() == f"rockjit: paused at {point}":
            return lines


def _signalled(argv, cwd, point, signum, how="script"):
    """Run, pause at ``point``, send ``signum``: (exit status, stderr)."""
    proc = _start(argv, cwd, point, how)
    lines = _until_paused(proc, point)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=300)
    return proc.returncode, "".join(lines) + err


def _entries(root):
    return sorted(p.name for p in Path(root).iterdir())


@pytest.mark.parametrize("name", SIGNALS)
def test_a_signal_during_the_imports(tmp_path, name):
    # Ctrl-C while the modules loaded ended in a KeyboardInterrupt traceback
    signum, status = SIGNALS[name]
    rc, err = _signalled(COR + ["--out", "o"], tmp_path, "imports", signum)
    assert rc == status and "Traceback" not in err, err
    assert err.rstrip().endswith(f"rockjit: interrupted ({name}); --out is as it was")
    assert _entries(tmp_path) == []


@pytest.mark.parametrize("how", ["script", "python -m"])
@pytest.mark.parametrize("name", SIGNALS)
def test_a_signal_during_the_work_leaves_out_as_it_was(tmp_path, name, how):
    signum, status = SIGNALS[name]
    out = tmp_path / "o"
    from rockjit.storage.output_dir import OutputDir
    with OutputDir(out) as earlier:  # an earlier run's (rockjit replaces only its own files)
        earlier.text("summary.json", "an earlier run's")
    rc, err = _signalled(COR + ["--out", "o"], tmp_path, "work", signum, how)
    assert rc == status and "Traceback" not in err, err
    assert f"rockjit: interrupted ({name}); --out is as it was" in err
    assert _entries(tmp_path) == ["o"] and _entries(out) == [".rockjit-files.json",
                                                              "summary.json"]
    assert (out / "summary.json").read_text() == "an earlier run's"


@pytest.mark.parametrize("point", ["published", "wrote"])
@pytest.mark.parametrize("name", SIGNALS)
def test_a_signal_after_publishing_changes_nothing(tmp_path, name, point):
    # in the instants after publication, SIGINT gave 130 and SIGTERM 143 although --out had
    # been updated, and the chunks were sometimes left behind
    signum, _ = SIGNALS[name]
    rc, err = _signalled(BASIN + ["--out", "o"], tmp_path, point, signum)
    assert rc == 0 and "Traceback" not in err, err
    assert f"rockjit: {name} arrived after o was written; the command has completed (exit " \
           f"status 0)" in err
    assert _entries(tmp_path) == ["o"]  # o.chunks removed all the same
    assert {"basin.npz", "summary.json"} <= set(_entries(tmp_path / "o"))


#: The console script, saying when the interpreter has started (no Python code runs before
#: the interpreter's own start-up, importing ``site``: a signal then is the interpreter's)
STARTED = "import sys; print('started', file=sys.stderr, flush=True); " + SCRIPT


@pytest.mark.parametrize("delay", [0.02, 0.5, 1.5, 3.0])
@pytest.mark.parametrize("name", SIGNALS)
def test_a_signal_at_any_moment_gives_one_outcome(tmp_path, name, delay):
    # unpaused: whenever it comes, the exit status says whether --out was published
    signum, status = SIGNALS[name]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-c", STARTED] + COR + ["--out", "o"], cwd=tmp_path,
                            env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=_default_sigint)
    assert proc.stderr.readline() == "started\n"
    time.sleep(delay)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=300)
    assert "Traceback" not in err, err
    if (tmp_path / "o" / "summary.json").is_file():
        assert proc.returncode == 0, err
    else:
        assert proc.returncode == status, err
        assert _entries(tmp_path) == [] and "--out is as it was" in err


# ---------------------------------------------------------------------------------------------
# in this process: a signal whose KeyboardInterrupt never reached the command
# ---------------------------------------------------------------------------------------------

COR_IN_PROCESS = ["cor", "--hb-values", "1", "--quiet"]


def test_a_signal_that_a_library_swallowed_still_interrupts(tmp_path, monkeypatch, capsys):
    from rockjit import outputs
    from rockjit.cli.main import main
    real = outputs.summary

    def swallowing(*args, **kwargs):
        try:  # as a library's `except BaseException: pass` would
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(0.5)  # the handler runs here, and its KeyboardInterrupt is lost
        except BaseException:
            pass
        return real(*args, **kwargs)

    monkeypatch.setattr(outputs, "summary", swallowing)
    out = tmp_path / "o"
    assert main(COR_IN_PROCESS + ["--out", str(out)]) == 143
    assert "rockjit: interrupted (SIGTERM); --out is as it was" in capsys.readouterr().err
    assert _entries(tmp_path) == []


class _SignalsWhenCollected:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(100_000):  # the handler runs in here: a finalizer cannot raise
            pass


def test_a_signal_during_a_finalizer_still_interrupts_quietly(tmp_path, monkeypatch, capsys):
    from rockjit import outputs
    from rockjit.cli.main import main
    real = outputs.summary

    def collecting(*args, **kwargs):
        _SignalsWhenCollected()  # collected at once
        return real(*args, **kwargs)

    monkeypatch.setattr(outputs, "summary", collecting)
    out = tmp_path / "o"
    assert main(COR_IN_PROCESS + ["--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert "Exception ignored" not in err and "Traceback" not in err, err
    assert err.strip() == "rockjit: interrupted (SIGINT); --out is as it was"
    assert _entries(tmp_path) == []

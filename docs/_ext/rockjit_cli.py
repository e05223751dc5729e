"""Sphinx extension: the command-line reference, generated from rockjit's argparse parser.

At ``builder-inited`` it walks :func:`rockjit.cli.main.build_parser` and writes
``docs/_generated/cli.md`` (MyST Markdown, git-ignored): for every command, in the parser's
order, its description, its usage line as argparse prints it, and a table of its options with
their defaults and help. ``docs/guide/cli.md`` includes that file, so the page always lists
every command and every option the installed parser has; nothing is written by hand.

Each command's heading carries the target ``cli-<command>`` for ``{ref}`` links.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

GENERATED = "_generated"
WIDTH = "92"  # columns for argparse's usage lines


def _escape(text):
    """Text for a Markdown table cell."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _invocation(action):
    """``--alpha-range START END`` as argparse's help would write it."""
    fmt = argparse.HelpFormatter("rockjit")
    return fmt._format_action_invocation(action)


def _default(action):
    d = action.default
    if d is None or d is False or d is argparse.SUPPRESS or isinstance(action, (
            argparse._HelpAction, argparse._VersionAction)):
        return ""
    if action.nargs not in (None, "?") and isinstance(d, (list, tuple)):
        return " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in d)
    if d is True:
        return "on"
    return f"{d:g}" if isinstance(d, float) else str(d)


def _help(action):
    text = action.help or ""
    if "%(" in text:
        text = text % dict(vars(action), prog="rockjit")
    if action.choices:
        text += f" (one of: {', '.join(map(str, action.choices))})"
    return text


def _exclusive(parser):
    """``{dest: [other option strings]}`` for options in mutually exclusive groups."""
    out = {}
    for group in parser._mutually_exclusive_groups:
        for a in group._group_actions:
            out[a.dest] = [o.option_strings[0] for o in group._group_actions if o is not a]
    return out


def _options_table(parser):
    rows = []
    excl = _exclusive(parser)
    for a in parser._actions:
        if isinstance(a, argparse._HelpAction):
            continue
        meaning = _help(a)
        if a.required:
            meaning = "**required**. " + meaning
        if a.dest in excl:
            meaning += " (not with " + ", ".join(f"`{o}`" for o in excl[a.dest]) + ")"
        default = _default(a)
        rows.append(f"| `{_invocation(a)}` | {_escape(default) and f'`{_escape(default)}`'} | "
                    f"{_escape(meaning)} |")
    if not rows:
        return ""
    return "| option | default | meaning |\n|---|---|---|\n" + "\n".join(rows) + "\n"


def _subparsers(parser):
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            helps = {c.dest: c.help for c in a._choices_actions}
            return [(name, p, helps.get(name, "")) for name, p in a.choices.items()]
    return []


def render(parser=None):
    """The reference as MyST Markdown (a string)."""
    if parser is None:
        from rockjit.cli.main import build_parser
        old = os.environ.get("COLUMNS")
        os.environ["COLUMNS"] = WIDTH
        try:
            parser = build_parser()
            return render(parser)
        finally:
            if old is None:
                os.environ.pop("COLUMNS", None)
            else:
                os.environ["COLUMNS"] = old
    commands = _subparsers(parser)
    lines = ["<!-- generated from rockjit.cli.main.build_parser() by docs/_ext/rockjit_cli.py: "
             "do not edit -->", ""]
    lines += ["| command | what it does |", "|---|---|"]
    lines += [f"| [`rockjit {name}`](#cli-{name}) | {_escape(h)} |" for name, _, h in commands]
    lines += ["", "```text", parser.format_usage().rstrip(), "```", "",
              "Global options: " + ", ".join(
                  f"`{_invocation(a)}` ({_escape(_help(a))})" for a in parser._actions
                  if not isinstance(a, argparse._SubParsersAction)) + ".", ""]
    for name, p, h in commands:
        lines += [f"(cli-{name})=", f"## `rockjit {name}`", ""]
        if p.description:
            lines += [" ".join(p.description.split()), ""]
        lines += ["```text", p.format_usage().rstrip(), "```", ""]
        table = _options_table(p)
        if table:
            lines += [table]
    return "\n".join(lines).rstrip() + "\n"


def write_if_changed(path, text):
    path = Path(path)
    if path.exists() and path.read_text() == text:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def _generate(app, config=None):
    write_if_changed(Path(app.srcdir) / GENERATED / "cli.md", render())


def setup(app):
    app.connect("config-inited", _generate)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}

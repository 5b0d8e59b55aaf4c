"""Silence the console output of palpate's Rust code (progress, FE
summaries, ``wrote`` lines) while a library call runs, unless asked.

The Rust code writes to the process's file descriptors 1 and 2, which
Python's ``sys.stdout``/``sys.stderr`` cannot capture, so the descriptors
themselves are pointed at the null device for the call. Calls running at
the same time in several threads share one redirection (a count under a
lock): the descriptors come back when the last of them returns. While a
quiet call runs, other output written to those descriptors by the same
process is silenced too.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading

_lock = threading.Lock()
_depth = 0
_saved: tuple[int, int] | None = None


def _flush() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, ValueError, OSError):
            pass


@contextlib.contextmanager
def quiet(enabled: bool = True):
    """Within the block, descriptors 1 and 2 write to the null device (if ``enabled``)."""
    global _depth, _saved
    if not enabled:
        yield
        return
    with _lock:
        if _depth == 0:
            _flush()
            null = os.open(os.devnull, os.O_WRONLY)
            _saved = (os.dup(1), os.dup(2))
            os.dup2(null, 1)
            os.dup2(null, 2)
            os.close(null)
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0 and _saved is not None:
                _flush()
                out, err = _saved
                os.dup2(out, 1)
                os.dup2(err, 2)
                os.close(out)
                os.close(err)
                _saved = None

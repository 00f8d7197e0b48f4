"""The private copies of test files that the steps read, and the sweep of those a kill left.

Each task copies its test file's bytes into a directory of its own under the
system's temporary directory, named ``tyredamp-campaign-<pid>-<random>`` and
holding a marker file (:data:`MARKER`); the directory is removed when the
task ends. A process killed with ``kill -9`` cannot remove it: the next
campaign run (and every worker process, once) sweeps the directories that
carry our name and our marker, belong to this user, and whose process is no
longer running. Nothing else is ever removed.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["MARKER", "PREFIX", "scratch_dir", "sweep_scratch"]

#: Start of the name of every scratch directory (then ``<pid>-<random>``).
PREFIX = "tyredamp-campaign-"
#: The file that marks a scratch directory as written by a campaign.
MARKER = ".tyredamp-campaign-scratch"
_NAME = re.compile(rf"^{re.escape(PREFIX)}(\d+)-[A-Za-z0-9_]+$")
_swept_in: set[int] = set()


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def sweep_scratch(root: str | os.PathLike[str] | None = None) -> list[Path]:
    """Remove the scratch directories that dead campaign processes left in ``root``.

    ``root`` defaults to the system's temporary directory. A directory is
    removed only when its name is ours (:data:`PREFIX`, a process id, a
    random part), it holds :data:`MARKER`, it belongs to this user, is not a
    link, and its process is not running.

    Returns
    -------
    list of Path
        The directories removed.
    """
    base = Path(tempfile.gettempdir() if root is None else root)
    removed: list[Path] = []
    try:
        entries = list(os.scandir(base))
    except OSError:
        return removed
    uid = os.getuid() if hasattr(os, "getuid") else None
    for e in entries:
        m = _NAME.match(e.name)
        if m is None or not e.is_dir(follow_symlinks=False):
            continue
        pid = int(m.group(1))
        if pid == os.getpid() or _running(pid):
            continue
        try:
            st = e.stat(follow_symlinks=False)
            if uid is not None and st.st_uid != uid:
                continue
            if not os.path.isfile(os.path.join(e.path, MARKER)):
                continue
        except OSError:
            continue
        shutil.rmtree(e.path, ignore_errors=True)
        if not os.path.lexists(e.path):
            removed.append(Path(e.path))
    return removed


def sweep_once() -> None:
    """:func:`sweep_scratch` once per process (workers call it before their first task)."""
    if os.getpid() not in _swept_in:
        _swept_in.add(os.getpid())
        sweep_scratch()


@contextlib.contextmanager
def scratch_dir() -> Iterator[Path]:
    """A private scratch directory (:data:`PREFIX` + pid, with :data:`MARKER`), removed after."""
    path = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-"))
    try:
        (path / MARKER).write_bytes(b"")
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)

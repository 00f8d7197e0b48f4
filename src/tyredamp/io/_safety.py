"""The one output-safety layer: every file and directory tyredamp writes goes through here.

The promises (stated in docs/reference/safety.md and tested by
``tests/test_badinput.py``):

* An output appears whole or not at all: it is written to a temporary beside
  the target (``.NAME.tyredamp-PID-XXXXXXXX.tmp``), flushed to disk
  (``fsync``) and renamed onto the target. On any error or interruption the
  temporary is removed and the target is unchanged.
* Commands that write several files write all of them or none
  (:func:`atomic_paths`): a target replaced before a later one failed is put
  back.
* ``--out`` may replace only a regular, writable file that is not one of the
  command's inputs (compared as real files: same device and inode, so
  ``./sub/../FILE``, symbolic and hard links are caught); a directory output
  may replace only an empty directory or an earlier output holding nothing
  but the files that output listed. Symbolic links are followed: the file or
  directory the link points to is written, the link itself is kept. A
  character device (``/dev/null``) is written directly, never renamed over;
  other special files (FIFO, socket, block device) are refused.
* Output paths that cannot work (empty, a directory, a missing parent
  directory, a read-only file or directory) are refused by
  :func:`check_output_file` / :func:`check_output_dir` before any work.
* Temporaries left by a killed earlier run for the same target are removed on
  the next write (:func:`sweep_stale`): only names of our own pattern, only
  from a process that no longer runs, only older than the running process.
* Error messages name the path the user gave, never the temporary.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import secrets
import shutil
import signal
import stat
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path

from ..exceptions import InputError

__all__ = [
    "MANIFEST_NAME",
    "PROCESS_START",
    "atomic_dir",
    "atomic_path",
    "atomic_paths",
    "check_distinct",
    "check_output_dir",
    "check_output_file",
    "private_matplotlib_config",
    "sweep_stale",
    "temp_name",
]

#: Wall-clock time this module was imported (a bound on the running process's age):
#: only temporaries older than this are ever swept.
PROCESS_START = time.time()

_TAG = "tyredamp"
_SUFFIXES = ("tmp", "old")


def temp_name(target_name: str, suffix: str = "tmp") -> str:
    """The hidden name of a temporary for ``target_name``: ``.NAME.tyredamp-PID-RAND.SUFFIX``."""
    return f".{target_name}.{_TAG}-{os.getpid()}-{secrets.token_hex(4)}.{suffix}"


def _stale_pattern(target_name: str) -> re.Pattern[str]:
    # ours: .NAME.tyredamp-PID-RAND.tmp|old; earlier releases: .NAME.XXXXXXXX.tmp (mkstemp)
    name = re.escape(target_name)
    return re.compile(
        rf"^\.{name}\.(?:{_TAG}-(?P<pid>\d+)-[0-9a-f]+|[a-z0-9_]{{8}})\.(?P<kind>tmp|old)$"
    )


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


def sweep_stale(target: str | os.PathLike[str]) -> list[Path]:
    """Remove temporaries of ``target`` left behind by an earlier, killed run.

    Only entries beside ``target`` whose name matches our own temporary pattern
    for this target name, that are regular files or directories (never links),
    whose process no longer runs and that are older than the running process
    are removed. A ``.old`` backup is removed only when ``target`` exists (else
    it may hold the only copy of an earlier output).

    Returns
    -------
    list of Path
        What was removed.
    """
    t = Path(target)
    parent = t.parent
    pat = _stale_pattern(t.name)
    removed: list[Path] = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    for e in entries:
        m = pat.match(e.name)
        if m is None:
            continue
        try:
            st = e.stat(follow_symlinks=False)
        except OSError:
            continue
        if not (stat.S_ISREG(st.st_mode) or stat.S_ISDIR(st.st_mode)):
            continue
        if st.st_mtime >= PROCESS_START:
            continue
        pid = m.group("pid")
        if pid is not None and _pid_alive(int(pid)):
            continue
        if m.group("kind") == "old" and not os.path.lexists(t):
            continue
        p = Path(e.path)
        try:
            if stat.S_ISDIR(st.st_mode):
                shutil.rmtree(p)
            else:
                p.unlink()
            removed.append(p)
        except OSError:
            continue
    return removed


# ----------------------------------------------------------------------------- checks
def _kind_of(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISDIR(mode):
        return "a directory"
    return "not a regular file"


def _same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output_file(
    out: str | os.PathLike[str],
    inputs: Iterable[str | os.PathLike[str] | None] = (),
    option: str = "--out",
) -> Path:
    """Refuse an output file path that cannot work or would destroy data; before any work.

    Parameters
    ----------
    out : path-like
        The path as the user gave it.
    inputs : iterable of path-like
        Every file the command reads (``None`` entries are skipped).
    option : str
        Name of the option, for the message.

    Returns
    -------
    Path
        ``out`` as given (the writers follow links themselves).

    Raises
    ------
    InputError
        Empty path, a directory, a special file other than a character device,
        a read-only file, a missing or read-only parent directory, or one of the
        inputs (same real file).
    """
    text = os.fspath(out)
    if text == "":
        raise InputError(f"{option}: empty path; expected a file name")
    p = Path(text)
    real = Path(os.path.realpath(p))
    if os.path.lexists(p) and os.path.exists(real):
        st = os.stat(real)
        if stat.S_ISDIR(st.st_mode):
            raise InputError(f"{option}: {text} is a directory; expected a file name")
        if not stat.S_ISREG(st.st_mode) and not stat.S_ISCHR(st.st_mode):
            raise InputError(
                f"{option}: {text} is {_kind_of(st.st_mode)}; tyredamp writes regular files "
                "(or a character device such as /dev/null)"
            )
        if stat.S_ISREG(st.st_mode) and not os.access(real, os.W_OK):
            raise InputError(f"{option}: {text} is read-only; not replaced")
    else:
        parent = real.parent
        if not parent.is_dir():
            raise InputError(f"{option}: {text}: the directory {parent} does not exist")
    if not stat.S_ISCHR(_mode(real)) and not os.access(real.parent, os.W_OK | os.X_OK):
        raise InputError(f"{option}: {text}: the directory {real.parent} is not writable")
    for inp in inputs:
        if inp is None or os.fspath(inp) == "":
            continue
        if _same_file(p, inp) or (os.path.exists(inp) and real == Path(os.path.realpath(inp))):
            raise InputError(
                f"{option}: {text} is the input file {os.fspath(inp)}; choose another name"
            )
    return p


def check_distinct(outputs: Sequence[tuple[str, str | os.PathLike[str] | None]]) -> None:
    """Refuse two output options naming the same file (``[(option, path), ...]``)."""
    seen: dict[str, str] = {}
    for opt, path in outputs:
        if path is None:
            continue
        key = os.path.realpath(path)
        if key in seen:
            raise InputError(f"{opt}: {os.fspath(path)} is also the {seen[key]} file")
        seen[key] = opt


def _mode(p: Path) -> int:
    try:
        return os.stat(p).st_mode
    except OSError:
        return 0


def check_output_dir(
    out: str | os.PathLike[str],
    owned_files: Callable[[Path], Sequence[str] | None],
    option: str = "--out",
    what: str = "tyredamp output",
    manifest: bool = True,
) -> Path:
    """Refuse an output directory that cannot work or holds data that is not ours; before work.

    Parameters
    ----------
    out : path-like
        The directory as the user gave it (a symbolic link is followed).
    owned_files : callable
        ``owned_files(real_dir)`` returns the relative paths an earlier output
        in that directory wrote (from its own file list), or ``None`` when the
        directory is not an earlier output.
    option : str
        Name of the option, for the message.
    what : str
        What an earlier output is called, for the message.
    manifest : bool
        The earlier output was written whole by :func:`atomic_dir`: its files must
        also be unchanged according to its manifest (:data:`MANIFEST_NAME`). False
        for outputs that grow file by file (a campaign's cache), whose files are
        only ever added or rewritten by the same content-keyed step.

    Returns
    -------
    Path
        The real directory (links followed) that will be written.

    Raises
    ------
    InputError
        Empty path; the current directory or one containing it; a file; a
        non-empty directory that is not an earlier output or holds anything
        that output did not write; a missing or read-only parent directory.
    """
    text = os.fspath(out)
    if text == "":
        raise InputError(f"{option}: empty path; expected a directory name")
    real = Path(os.path.realpath(text))
    cwd = Path(os.path.realpath(os.getcwd()))
    if real == cwd or real in cwd.parents or real.parent == real:
        raise InputError(
            f"{option}: {text} is the current directory or contains it; choose a new directory"
        )
    if not real.parent.is_dir():
        raise InputError(f"{option}: {text}: the directory {real.parent} does not exist")
    if not os.access(real.parent, os.W_OK | os.X_OK):
        raise InputError(f"{option}: {text}: the directory {real.parent} is not writable")
    if not os.path.lexists(real):
        return real
    if not real.is_dir():
        raise InputError(f"{option}: {text} exists and is not a directory")
    present = _listing(real)
    if not present:
        return real
    owned = owned_files(real)
    if owned is None:
        raise InputError(
            f"{option}: {text} exists and is not an earlier {what}; "
            "choose another directory or remove it"
        )
    allowed = set()
    for f in owned:
        parts = Path(f).parts
        for k in range(1, len(parts) + 1):
            allowed.add(Path(*parts[:k]).as_posix())
    allowed.add(MANIFEST_NAME)
    extra = sorted(x for x in present if x not in allowed)
    if extra:
        raise InputError(
            f"{option}: {text} holds files an earlier {what} did not write ({_few(extra)}); "
            "not replaced: choose another directory or move them"
        )
    mine = [f for f in owned if f != MANIFEST_NAME and (real / f).is_file()]
    changed = changed_since_written(real, mine) if manifest else []
    if changed:
        raise InputError(
            f"{option}: {text}: {_few(changed)} changed since tyredamp wrote it; "
            "not replaced: choose another directory or move the changed files"
        )
    return real


def _few(names: Sequence[str]) -> str:
    return ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")


#: Written last into every directory that :func:`atomic_dir` puts in place: the
#: SHA-256 of each file, so that a later run replaces only files nobody has changed.
MANIFEST_NAME = ".tyredamp-manifest.json"


def _sha256(p: Path) -> str:
    h = hashlib.sha256()
    with open(p, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _write_manifest(root: Path) -> None:
    """Record the SHA-256 of every file under ``root`` in ``root/MANIFEST_NAME``."""
    files: dict[str, str] = {}
    for dirpath, _dirnames, filenames in os.walk(root):
        for f in filenames:
            p = Path(dirpath) / f
            rel = p.relative_to(root).as_posix()
            if rel != MANIFEST_NAME:
                files[rel] = _sha256(p)
    doc = {"kind": "tyredamp-manifest", "version": 1, "sha256": dict(sorted(files.items()))}
    (root / MANIFEST_NAME).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def changed_since_written(root: Path, files: Sequence[str]) -> list[str]:
    """The files of ``files`` (relative to ``root``) that are not as tyredamp wrote them.

    A file counts as changed when the directory's manifest (:data:`MANIFEST_NAME`)
    gives it another SHA-256, or does not list it; without a readable manifest
    (an output of an older tyredamp, or a damaged manifest) every file counts as
    changed, since nothing proves it is not the user's.
    """
    try:
        doc = json.loads((root / MANIFEST_NAME).read_text(encoding="utf-8"))
        known = doc["sha256"]
        if not isinstance(known, dict):
            raise TypeError("sha256")
    except (OSError, ValueError, RecursionError, TypeError, KeyError):
        return sorted(files)
    return sorted(f for f in files if known.get(f) != _sha256(root / f))


def _listing(root: Path) -> set[str]:
    """Relative paths (files, links and directories) under ``root``, links not followed."""
    out: set[str] = set()
    for dirpath, dirnames, filenames in os.walk(root):
        rel = Path(dirpath).relative_to(root)
        for n in [*dirnames, *filenames]:
            out.add((rel / n).as_posix())
    return out


# ----------------------------------------------------------------------------- writing
def _fsync_file(p: Path) -> None:
    fd = os.open(p, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(p: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(p, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


@contextlib.contextmanager
def _signals_blocked() -> Iterator[None]:
    """Hold SIGINT and SIGTERM back while files are moved into place.

    A signal between two renames would otherwise leave one target replaced and
    its backup gone; held back, it arrives when every target is in place.
    """
    sigs = {signal.SIGINT, signal.SIGTERM}
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, sigs)
    except (AttributeError, OSError, ValueError):  # pragma: no cover - not POSIX
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _keep_mode(tmp: Path, target: Path) -> None:
    """Give ``tmp`` the mode of the file it replaces (a private file stays private),
    else the usual mode for a new file."""
    try:
        st = os.stat(target)
    except OSError:
        _usual_mode(tmp)
        return
    if stat.S_ISREG(st.st_mode):
        os.chmod(tmp, stat.S_IMODE(st.st_mode))
    else:
        _usual_mode(tmp)


def _usual_mode(p: Path, directory: bool = False) -> None:
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(p, (0o777 if directory else 0o666) & ~umask)


def _rename_error(exc: OSError, names: dict[str, str]) -> OSError:
    """``exc`` with temporary names replaced by the user's names (same errno).

    An error without a file name (``No space left on device`` while writing)
    gets the user's target, so that the one error line says which file failed.
    """
    fn = exc.filename
    if isinstance(fn, str | os.PathLike):
        for tmp, user in names.items():
            if os.fspath(fn) == tmp or tmp in os.fspath(fn):
                where = os.fspath(fn).replace(tmp, user)
                return OSError(exc.errno, _user_text(exc.strerror or str(exc), names), where)
        return exc
    users = list(dict.fromkeys(names.values()))
    if fn is None and users and exc.errno is not None:
        return OSError(exc.errno, _user_text(exc.strerror or str(exc), names), ", ".join(users))
    return exc


def _user_text(text: str, names: dict[str, str]) -> str:
    """``text`` with every temporary name replaced by the user's name of its target."""
    for tmp, user in names.items():
        text = text.replace(tmp, user)
    return text


def _renamed(exc: BaseException, names: dict[str, str]) -> BaseException:
    """A tyredamp error whose message names a temporary, re-made naming the target."""
    from ..exceptions import TyredampError

    text = str(exc)
    if not isinstance(exc, TyredampError) or not any(t in text for t in names):
        return exc
    try:
        return type(exc)(_user_text(text, names))
    except Exception:  # pragma: no cover - an error class with another signature
        return exc


class _Target:
    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.given = os.fspath(path)
        if self.given == "":
            raise InputError("output path: empty; expected a file name")
        self.real = Path(os.path.realpath(self.given))
        self.direct = stat.S_ISCHR(_mode(self.real))
        self.tmp: Path | None = None
        self.backup: Path | None = None


@contextlib.contextmanager
def atomic_paths(paths: Sequence[str | os.PathLike[str]]) -> Iterator[list[Path]]:
    """Yield one temporary path per target; move all of them into place on success.

    All targets are replaced, or none: a target already replaced when a later
    one fails is restored from its backup. On any exception (including an
    interruption) every temporary is removed and every target is unchanged.
    Symbolic links are followed (the file they point to is replaced); a
    character device such as ``/dev/null`` is written directly.

    Parameters
    ----------
    paths : sequence of path-like
        The files to write, as the user gave them.

    Yields
    ------
    list of Path
        Where to write each file (a temporary beside the real target).
    """
    targets = [_Target(p) for p in paths]
    names: dict[str, str] = {}
    try:
        for t in targets:
            if t.direct:
                # a device is never renamed over: the data go to a private temporary
                # first (formats such as NPZ need a seekable file) and are then copied
                fd, name = tempfile.mkstemp(prefix="tyredamp-", suffix=".tmp")
                os.close(fd)
                t.tmp = Path(name)
                names[name] = t.given
                continue
            if not t.real.parent.is_dir():
                t.real.parent.mkdir(parents=True, exist_ok=True)
            sweep_stale(t.real)
            tmp = t.real.parent / temp_name(t.real.name)
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.close(fd)
            t.tmp = tmp
            names[str(tmp)] = t.given
        yield [t.real if t.tmp is None else t.tmp for t in targets]
        for t in targets:
            if t.tmp is not None and not t.direct:
                _fsync_file(t.tmp)
                _keep_mode(t.tmp, t.real)
        with _signals_blocked():
            _commit(targets, names)
    except OSError as exc:
        _cleanup(targets)
        raise _rename_error(exc, names) from None
    except BaseException as exc:
        _cleanup(targets)
        new = _renamed(exc, names)
        if new is exc:
            raise
        raise new from None


def _commit(targets: list[_Target], names: dict[str, str]) -> None:
    done: list[_Target] = []
    try:
        for t in targets:
            if t.tmp is None:
                continue
            if t.direct:
                continue
            if len(targets) > 1 and os.path.lexists(t.real):
                t.backup = t.real.parent / temp_name(t.real.name, "old")
                names[str(t.backup)] = t.given
                try:
                    os.link(t.real, t.backup)
                except OSError:
                    t.backup = None
                    # no hard links here: keep a copy instead
                    b = t.real.parent / temp_name(t.real.name, "old")
                    shutil.copy2(t.real, b)
                    t.backup = b
            os.replace(t.tmp, t.real)
            t.tmp = None
            done.append(t)
            _fsync_dir(t.real.parent)
    except BaseException:
        for t in reversed(done):
            if t.backup is not None:
                with contextlib.suppress(OSError):
                    os.replace(t.backup, t.real)
                    t.backup = None
            else:
                with contextlib.suppress(OSError):
                    t.real.unlink()
        raise
    for t in targets:
        if t.backup is not None:
            with contextlib.suppress(OSError):
                t.backup.unlink()
            t.backup = None
    for t in targets:  # devices last: what is sent there cannot be taken back
        if t.direct and t.tmp is not None:
            with open(t.tmp, "rb") as src, open(t.real, "wb") as dst:
                shutil.copyfileobj(src, dst)
            t.tmp.unlink()
            t.tmp = None


def _cleanup(targets: list[_Target]) -> None:
    for t in targets:
        for p in (t.tmp, t.backup if t.backup is not None and os.path.lexists(t.real) else None):
            if p is not None:
                with contextlib.suppress(OSError):
                    p.unlink()
        t.tmp = None


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it onto ``path`` on success.

    On any exception the temporary file is removed and ``path`` is untouched,
    so no partial output is ever left behind (see :func:`atomic_paths`).
    """
    with atomic_paths([path]) as tmps:
        yield tmps[0]


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary directory beside ``path``; put it in place of ``path`` on success.

    The caller checks first (:func:`check_output_dir`) that an existing
    ``path`` may be replaced. Links are followed. On success the tree is
    flushed (``fsync``), given the usual permissions and renamed onto the
    target; an existing target is moved aside first and put back if the
    rename fails. On any exception the temporary directory is removed and the
    target is unchanged.
    """
    given = os.fspath(path)
    real = Path(os.path.realpath(given))
    real.parent.mkdir(parents=True, exist_ok=True)
    sweep_stale(real)
    tmp = real.parent / temp_name(real.name)
    os.mkdir(tmp, 0o700)
    names = {str(tmp): given}
    try:
        yield tmp
        _write_manifest(tmp)
        for dirpath, dirnames, filenames in os.walk(tmp):
            for f in filenames:
                _fsync_file(Path(dirpath) / f)
                _usual_mode(Path(dirpath) / f)
            for d in dirnames:
                _usual_mode(Path(dirpath) / d, directory=True)
        _usual_mode(tmp, directory=True)
        with _signals_blocked():
            if not os.path.lexists(real):
                os.replace(tmp, real)
            else:
                old = real.parent / temp_name(real.name, "old")
                os.replace(real, old)
                try:
                    os.replace(tmp, real)
                except BaseException:
                    os.replace(old, real)
                    raise
                shutil.rmtree(old, ignore_errors=True)
        _fsync_dir(real.parent)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise _rename_error(exc, names) from None
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        new = _renamed(exc, names)
        if new is exc:
            raise
        raise new from None


# ----------------------------------------------------------------------------- matplotlib
@contextlib.contextmanager
def private_matplotlib_config() -> Iterator[None]:
    """Point matplotlib's config and cache at a private temporary directory.

    Only when ``MPLCONFIGDIR`` is not set already (a user's choice is kept) and
    matplotlib is not imported yet; the directory is removed afterwards, so
    nothing is written into the user's home.
    """
    import sys

    if os.environ.get("MPLCONFIGDIR") or "matplotlib" in sys.modules:
        yield
        return
    d = tempfile.mkdtemp(prefix="tyredamp-mpl-")
    os.environ["MPLCONFIGDIR"] = d
    try:
        yield
    finally:
        os.environ.pop("MPLCONFIGDIR", None)
        shutil.rmtree(d, ignore_errors=True)

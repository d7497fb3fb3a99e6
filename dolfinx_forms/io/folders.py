"""Result folders (`--out`): written atomically, never deleting what this code did not write.

Every result folder holds a marker file MARKER (`.ils_result`, JSON: the program, the time and
the relative paths of every file and folder it wrote). Rules for `--out PATH`:

* PATH missing: the results appear there in one rename of a finished temporary folder.
* PATH an empty folder: replaced by one rename. PATH a result folder of this code holding
  nothing but what its marker lists: replaced in one atomic exchange (renameat2
  RENAME_EXCHANGE; two renames where the filesystem lacks it), then the old results removed.
* PATH holds anything else (no marker, or files the marker does not list): refused with
  ``--out: PATH exists and is not a result folder of this code (use another path or --force)``,
  exit status 2, when the arguments are parsed (before any computation) and again before the
  results are moved in. With ``--force`` our files are added next to what is there (existing
  folders merged, each file moved in atomically, the marker written last); files of an
  earlier result of ours that are not written again are removed; files and folders the
  marker does not list are never deleted or overwritten (a name clash is an error and
  nothing is moved).
* PATH a file, '' or '.', the current folder or one of its parents, the filesystem root, the
  home folder, or (running from a source tree) the repository root or a package's source
  folder: always refused, also with ``--force``.

Folders get the permissions 0o777 & ~umask (mkdtemp makes 0o700), files those of open().
SIGINT/SIGTERM while the results are written remove the temporary folder (it never carries
the final name); the final move runs with both signals blocked.
"""

import ctypes
import json
import os
import shutil
import signal
import tempfile
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from dolfinx_forms.common import signals_unwind

MARKER = ".ils_result"
# names the programs of this repository write at the top of a result folder: with --force a
# foreign entry of one of these names is refused when the arguments are parsed
RESULT_NAMES = (
    "metrics.json",
    "tractions.csv",
    "tractions.png",
    "solution.xdmf",
    "solution.h5",
    "contact_points.csv",
    "contact_geometry.png",
    "convergence.json",
    "convergence.png",
    "runs",
    MARKER,
)


class OutputFolderError(ValueError):
    """A refused --out (the message is one line starting with '--out:')."""


def umask() -> int:
    """The process umask, read without changing it where /proc allows."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # fallback: set and restore at once
    os.umask(mask)
    return mask


def dir_mode() -> int:
    return 0o777 & ~umask()


def read_marker(folder):
    """The marker of `folder` as a dict with 'program' and 'files' (a set), or None."""
    try:
        data = json.loads((Path(folder) / MARKER).read_text())
        if isinstance(data, dict) and isinstance(data.get("files"), list):
            return dict(data, files=set(map(str, data["files"])))
    except (OSError, ValueError):
        pass
    return None


def tree(folder) -> set:
    """Relative POSIX paths of every file and folder below `folder` (the marker excluded)."""
    folder = Path(folder)
    out = set()
    for dirpath, dirnames, filenames in os.walk(folder):
        rel = Path(dirpath).relative_to(folder)
        for name in dirnames + filenames:
            out.add((rel / name).as_posix())
    out.discard(MARKER)
    return out


def folder_state(out: Path) -> str:
    """'missing', 'empty', 'ours' (a result folder holding only what its marker lists) or
    'foreign'; OutputFolderError if `out` is not a folder or cannot be read."""
    if not os.path.lexists(out):
        return "missing"
    if not out.is_dir():
        raise OutputFolderError(f"--out: {out} exists and is not a folder")
    try:
        entries = tree(out) | ({MARKER} if (out / MARKER).exists() else set())
    except OSError as e:
        raise OutputFolderError(f"--out: cannot read {out}: {e.strerror}")
    if not entries:
        return "empty"
    marker = read_marker(out)
    if marker is not None and tree(out) <= marker["files"]:
        return "ours"
    return "foreign"


def _source_folders():
    """{path: what} of the repository root and the packages' source folders when this code
    runs from a source tree (pyproject.toml next to the package), else {}."""
    root = Path(__file__).resolve().parents[2]  # dolfinx_forms/io/folders.py
    if not (root / "pyproject.toml").is_file():
        return {}
    out = {root: "the repository root"}
    for name in ("dolfinx_forms", "meshes"):
        out[root / name] = f"the source folder of the package {name}"
    return out


def _forbidden(text: str, path: Path):
    """Why `path` may never be a result folder, or None."""
    if text.strip() in ("", "."):
        return "the current folder"
    if path == Path(path.anchor):
        return "the filesystem root"
    try:
        if path == Path.home().resolve():
            return "the home folder"
    except (RuntimeError, KeyError):  # no home folder defined
        pass
    cwd = Path.cwd().resolve()
    if path == cwd:
        return "the current folder"
    if path in cwd.parents:
        return "a parent of the current folder"
    return _source_folders().get(path)


def _not_ours(out: Path) -> str:
    return (
        f"--out: {out} exists and is not a result folder of this code (use another path or --force)"
    )


def _existing_ancestor(path):
    """The nearest existing folder at or above `path` (a name too long for the file system
    is not there)."""
    for anc in (path, *path.parents):
        try:
            if anc.exists():
                return anc
        except OSError:
            continue
    return Path("/")


def check_output_path(text, force=False) -> Path:
    """Validate --out before any computation; returns the resolved path.

    OutputFolderError (one line) for: '', '.', the current folder or a parent, the root, the
    home folder, an existing file, an existing folder that is neither empty nor a result
    folder of this code (allowed with force unless it holds a foreign entry named like one
    of RESULT_NAMES), or a path that cannot be created (probed by creating and removing a
    temporary folder in the nearest existing ancestor)."""
    text = "" if text is None else str(text)
    if text.strip() == "":
        raise OutputFolderError("--out: must be a folder path, got ''")
    out = Path(text).resolve()
    # the folder is built as ".<name>.XXXXXXXX.partial" beside it, then renamed
    longest = max(len(os.fsencode(c)) for c in out.parts)
    limit = os.pathconf(_existing_ancestor(out), "PC_NAME_MAX") - len(".._XXXXXXXX.partial")
    if longest > limit:
        raise OutputFolderError(
            f"--out: a folder name of at most {limit} bytes (the file system's limit less the "
            f"temporary folder's affixes), got one of {longest}"
        )
    why = _forbidden(text, out)
    if why:
        raise OutputFolderError(f"--out: {text} is {why}; give a folder of its own")
    state = folder_state(out)
    if state == "foreign":
        if not force:
            raise OutputFolderError(_not_ours(out))
        marker = read_marker(out)
        ours = marker["files"] if marker else set()
        clash = sorted(
            n
            for n in RESULT_NAMES
            if os.path.lexists(out / n)
            and n not in ours
            and not (n == MARKER and marker is not None)
        )
        if clash:
            raise OutputFolderError(
                f"--out: {out} holds {clash[0]!r}, which this code did not "
                f"write and would overwrite (use another path)"
            )
    anc = out if state != "missing" else out.parent
    while not anc.exists():
        anc = anc.parent
    if not anc.is_dir():
        raise OutputFolderError(f"--out: cannot create {out}: {anc} is not a folder")
    try:  # probe: a folder can be created where the results will go
        os.rmdir(tempfile.mkdtemp(prefix=".ils_probe.", dir=anc))
    except OSError as e:
        raise OutputFolderError(f"--out: cannot create {out} ({anc}: {e.strerror})")
    return out


# --------------------------------------------------------------------------- moving in
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap two paths (Linux renameat2); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    r = fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if r == 0:
        return True
    err = ctypes.get_errno()
    if err in (38, 22, 95):  # ENOSYS, EINVAL (filesystem without exchange), EOPNOTSUPP
        return False
    raise OSError(err, os.strerror(err), str(a))


def _write_marker(folder: Path, program: str, files, **extra):
    data = dict(
        program=program, written=time.strftime("%Y-%m-%dT%H:%M:%S%z"), files=sorted(files), **extra
    )
    tmp = folder / f"{MARKER}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    os.replace(tmp, folder / MARKER)


def _clashes(src: Path, dst: Path, rel: str, ours: set) -> list:
    """Entries of `src` that would replace something in `dst` this code did not write."""
    out = []
    for e in sorted(src.iterdir()):
        r, t = f"{rel}{e.name}", dst / e.name
        if r == MARKER or not os.path.lexists(t):
            continue
        if e.is_dir() and t.is_dir() and not t.is_symlink():
            out += _clashes(e, t, r + "/", ours)  # merge into the existing folder
        elif r not in ours or (t.is_dir() and not t.is_symlink()):
            out.append(r)
    return out


def _move_in(src: Path, dst: Path):
    """Move the entries of `src` into `dst` (checked by _clashes): files atomically replaced,
    new folders renamed in, existing folders merged."""
    for e in sorted(src.iterdir()):
        t = dst / e.name
        if e.is_dir() and t.is_dir() and not t.is_symlink():
            _move_in(e, t)
        else:
            os.replace(e, t)


def _merge(tmp: Path, out: Path, program: str):
    """--force into a folder with foreign content: our entries are moved in one by one (each
    file atomically), replacing only what an earlier marker of ours lists; files of that
    earlier result not written again are removed, foreign files and folders never; then the
    marker (written last) lists what is ours."""
    marker = read_marker(out)
    ours = marker["files"] if marker else set()
    clash = _clashes(tmp, out, "", ours)
    if clash:
        raise OutputFolderError(
            f"--out: {out / clash[0]} exists and was not written by this "
            f"code; nothing was moved (use another path)"
        )
    new = tree(tmp)
    _move_in(tmp, out)
    for rel in sorted(ours - new, key=lambda q: -q.count("/")):  # deepest first
        p = out / rel
        try:
            if p.is_dir() and not p.is_symlink():
                p.rmdir()  # only if empty: foreign content keeps it
            elif os.path.lexists(p):
                p.unlink()
        except OSError:
            pass
    keep = {q for q in ours | new if os.path.lexists(out / q)}
    _write_marker(out, program, keep, added_to_existing_folder=True)


def _commit(tmp: Path, out: Path, force: bool, program: str):
    """Move the finished folder `tmp` to `out` by the rules of the module doc."""
    state = folder_state(out)
    if state == "foreign" and not force:
        raise OutputFolderError(_not_ours(out))
    if state == "foreign":
        _merge(tmp, out, program)
        shutil.rmtree(tmp, ignore_errors=True)
        return
    _write_marker(tmp, program, tree(tmp))
    if state == "missing":
        os.rename(tmp, out)  # fails (nothing lost) if out appeared meanwhile
    elif state == "empty":
        os.replace(tmp, out)  # a folder onto an empty folder: atomic; ENOTEMPTY otherwise
    else:  # ours: swap, then remove the old results (now at tmp)
        if not _exchange(tmp, out):
            old = out.with_name(f".{out.name}.old.{os.getpid()}")
            os.rename(out, old)
            os.rename(tmp, out)
            tmp = old
        shutil.rmtree(tmp, ignore_errors=True)


@contextmanager
def _signals_blocked():
    main = threading.current_thread() is threading.main_thread()
    sigs = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, sigs) if main else None
    try:
        yield
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextmanager
def atomic_output_dir(out, comm=None, force=False, program=None):
    """Yield a temporary folder beside `out`, shared by all ranks of `comm` (default
    COMM_WORLD), which becomes `out` when the block succeeded on every rank (rules in the
    module doc; OutputFolderError on every rank if `out` is refused).

    If the block raises, this rank removes the temporary folder and re-raises without any
    collective call (the other ranks may be inside another collective): under mpirun the
    package's excepthook (parallel.py) then ends every rank."""
    from mpi4py import MPI

    from dolfinx_forms.common import program_name

    comm = MPI.COMM_WORLD if comm is None else comm
    program = program or program_name()
    tmp = None
    try:  # from the temporary folder's creation until every rank has written into it
        with signals_unwind():
            status = None
            if comm.rank == 0:
                try:
                    path = check_output_path(out, force)
                    path.parent.mkdir(parents=True, exist_ok=True)
                    tmp = tempfile.mkdtemp(
                        prefix=f".{path.name}.", suffix=".partial", dir=path.parent
                    )
                    os.chmod(tmp, dir_mode())
                    status = ("ok", str(path), tmp)
                except OSError as e:
                    status = ("error", f"--out: cannot write {out}: {e.strerror or e}")
                except OutputFolderError as e:
                    status = ("error", str(e))
            status = comm.bcast(status, root=0)
            if status[0] != "ok":
                raise OutputFolderError(status[1])
            path, tmp = Path(status[1]), Path(status[2])
            yield tmp
            comm.barrier()  # every rank has finished writing
    except BaseException:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        raise
    result = None
    if comm.rank == 0:
        with _signals_blocked():
            try:
                _commit(tmp, path, force, program)
                result = ("ok",)
            except (OSError, OutputFolderError) as e:
                shutil.rmtree(tmp, ignore_errors=True)
                msg = (
                    str(e)
                    if isinstance(e, OutputFolderError)
                    else f"--out: cannot move the results to {path}: {e.strerror or e}"
                )
                result = ("error", msg)
    result = comm.bcast(result, root=0)
    if result[0] != "ok":
        raise OutputFolderError(result[1])

"""Reading and writing the project's files safely: the one place for atomic writes and for
reading untrusted JSON and ``.npz`` files.

Writes go to a temporary file in the target's folder, are flushed and ``fsync``-ed, then renamed
over the target (``os.replace``), so a reader never sees half a file; on any failure (including
``KeyboardInterrupt``) the temporary file is removed and the target is left as it was.

Reads refuse, with one :class:`~core.errors.InputError` naming the file (and line/column where
one applies), everything that would otherwise surface later as a traceback or an enormous
allocation: files over a size limit, invalid UTF-8, JSON nested deeper than a limit (checked by a
bracket scan *before* :func:`json.loads` recurses), ``NaN``/``Infinity`` literals, embedded NUL
characters and lone surrogates in strings; ``.npz`` members whose header (read before any data)
claims more elements than a limit, object (pickled) arrays, empty files, corrupt zips and bad
CRCs. The limits live in :mod:`core.limits`.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import tempfile
import zipfile
import zlib
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import numpy as np

from core.errors import InputError
from core.limits import MAX_INPUT_BYTES, MAX_JSON_DEPTH, MAX_NPZ_ELEMENTS, MAX_NPZ_MEMBERS

# ---- writing -------------------------------------------------------------------------------------


def _read_umask() -> int:
    """The process's umask (read by setting it and putting it back: once, at import)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: Mode of a file written by :func:`atomic_open`: what a plain ``open()`` would give.
FILE_MODE = 0o666 & ~_read_umask()


@contextmanager
def atomic_open(path: str | os.PathLike, mode: str = "w") -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path``; on success it replaces ``path`` atomically.

    ``mode`` is ``"w"`` (UTF-8 text) or ``"wb"``. The parent folder is created. On any exception
    the temporary file is removed and the exception propagates.
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot write ({_reason(exc)})", printable(str(path))) from None
    try:
        encoding = "utf-8" if mode == "w" else None
        with os.fdopen(fd, mode, encoding=encoding) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        # mkstemp creates 0600; the file gets the mode a plain open() would (0666 less the umask)
        os.chmod(tmp, FILE_MODE)
        os.replace(tmp, path)
    except BaseException as exc:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise InputError(f"cannot write ({_reason(exc)})", str(path)) from None
        raise


def save_figure(fig: Any, path: str | os.PathLike, *, dpi: int = 100, **savefig: Any) -> Path:
    """Write a Matplotlib figure as PNG through :func:`atomic_open`; returns ``path``.

    ``savefig`` is passed on to ``fig.savefig`` (e.g. ``bbox_inches="tight"``). The figure is
    left open (the caller closes it).
    """
    path = Path(path)
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=dpi, **savefig)
    return path


def check_output_path(path: str | os.PathLike, *, what: str = "output file") -> Path:
    """``path`` as a :class:`Path` if a file can be written there (checked before long work):
    not a folder, its folder a folder (or creatable) and writable; else one line naming it."""
    path = Path(path)
    src = printable(str(path))
    try:
        if path.is_dir():
            raise InputError(f"{what} is a folder", src)
        parent = path.parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            raise InputError(f"cannot write {what}: {parent} is not a folder", src)
        if not os.access(parent, os.W_OK | os.X_OK):
            raise InputError(f"cannot write {what}: no permission in {parent}", src)
    except (OSError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"cannot write {what} ({_reason(exc)})", src) from None
    return path


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_open(path, "w") as fh:
        fh.write(text)
    return Path(path)


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    with atomic_open(path, "wb") as fh:
        fh.write(data)
    return Path(path)


def write_json_atomic(path: str | os.PathLike, doc: Any, *, indent: int | None = 2) -> Path:
    """Write ``doc`` as JSON (``indent``, trailing newline) to ``path`` atomically."""
    return write_text_atomic(path, json.dumps(doc, indent=indent) + "\n")


def write_npz_atomic(
    path: str | os.PathLike, arrays: dict[str, np.ndarray], *, compressed: bool = True
) -> Path:
    """Write ``arrays`` as an ``.npz`` (compressed by default) to ``path`` atomically."""
    save: Callable[..., None] = np.savez_compressed if compressed else np.savez
    with atomic_open(path, "wb") as fh:
        save(fh, **arrays)
    return Path(path)


# ---- reading -------------------------------------------------------------------------------------


def sources_hash(files: Iterable[Path], root: Path) -> str:
    """A cache-key part that changes with the code: 16 hex digits of sha256 over each existing
    file's path (relative to ``root``) and content, in the order given."""
    h = hashlib.sha256()
    for f in files:
        if f.is_file():
            h.update(f.relative_to(root).as_posix().encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def read_bytes(
    path: str | os.PathLike, *, what: str = "file", limit: int = MAX_INPUT_BYTES
) -> bytes:
    """The bytes of ``path``; refuses a missing, unreadable or too large file (one line)."""
    src = str(path)
    try:
        with open(path, "rb") as fh:
            size = os.fstat(fh.fileno()).st_size
            if size > limit:
                raise InputError(f"{what} is {size} bytes, more than the limit {limit}", src)
            data = fh.read(limit + 1)
    except FileNotFoundError:
        raise InputError(f"{what} not found", src) from None
    except IsADirectoryError:
        raise InputError(f"{what} is a directory", src) from None
    except (OSError, ValueError) as exc:  # ValueError: embedded NUL in the path
        raise InputError(f"cannot read {what} ({_reason(exc)})", printable(src)) from None
    if len(data) > limit:
        raise InputError(f"{what} is more than the limit of {limit} bytes", src)
    return data


def read_text(path: str | os.PathLike, *, what: str = "file", limit: int = MAX_INPUT_BYTES) -> str:
    """The UTF-8 text of ``path``; invalid UTF-8 is refused with its line and column."""
    return decode_utf8(read_bytes(path, what=what, limit=limit), str(path), what=what)


def decode_utf8(data: bytes, source: str, *, what: str = "file") -> str:
    """Decode UTF-8 (a leading BOM is dropped); an invalid byte is one line with its position."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(
            f"{what} is not UTF-8 text (byte 0x{data[exc.start]:02x} at column {col})",
            f"{source}:{line}",
        ) from None


def read_json(
    path: str | os.PathLike, *, what: str = "JSON file", limit: int = MAX_INPUT_BYTES
) -> Any:
    """Parse a JSON file with :func:`parse_json`; every failure is one line naming the file."""
    text = read_text(path, what=what, limit=limit)
    return parse_json(text, str(path), what=what)


def parse_json(
    text: str, source: str, *, what: str = "JSON", max_depth: int = MAX_JSON_DEPTH
) -> Any:
    """Parse JSON text strictly: one :class:`InputError` naming ``source:line`` for invalid
    JSON, nesting deeper than ``max_depth`` (checked before parsing), ``NaN``/``Infinity``
    literals, and strings holding a NUL character or a lone surrogate."""
    _check_depth(text, source, max_depth)

    def no_constant(name: str) -> Any:
        raise _JsonRefusal(f"{name} is not allowed in JSON (use a finite number)")

    try:
        data = json.loads(text, parse_constant=no_constant)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}",
            f"{source}:{exc.lineno}",
        ) from None
    except _JsonRefusal as exc:
        raise InputError(str(exc), source) from None
    except RecursionError:  # the depth scan makes this unreachable; kept as a last guard
        raise InputError(f"{what} is nested too deeply", source) from None
    bad = _bad_string(data) if _may_hold_bad_string(text) else None
    if bad is not None:
        raise InputError(f"{what} {bad}", source)
    return data


class _JsonRefusal(ValueError):
    pass


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)
_NOT_BRACKET_OR_NEWLINE = re.compile(r"[^\[\]{}\n]+")


def _check_depth(text: str, source: str, max_depth: int) -> None:
    """Refuse brackets nested deeper than ``max_depth`` outside strings, without recursion:
    strings are blanked and everything but brackets and newlines dropped (regular expressions),
    then the depth is a cumulative sum over the brackets."""
    kept = _NOT_BRACKET_OR_NEWLINE.sub("", _JSON_STRING.sub('""', text)).encode("ascii")
    chars = np.frombuffer(kept, dtype=np.uint8)
    step = np.zeros(len(chars), dtype=np.int64)
    step[(chars == ord("[")) | (chars == ord("{"))] = 1
    step[(chars == ord("]")) | (chars == ord("}"))] = -1
    depth = np.cumsum(step)
    too_deep = np.flatnonzero(depth > max_depth)
    if len(too_deep):
        line = int(np.count_nonzero(chars[: too_deep[0]] == ord("\n"))) + 1
        raise InputError(f"JSON nested deeper than {max_depth} levels", f"{source}:{line}")


_NUL_OR_SURROGATE_ESCAPE = re.compile(r"\\u(?:0000|d[89a-f][0-9a-f]{2})", re.IGNORECASE)


def _may_hold_bad_string(text: str) -> bool:
    """False when no parsed string can hold a NUL or a lone surrogate: JSON allows neither raw
    (control characters are invalid in strings; decoded UTF-8 has no surrogates), so only their
    ``\\u`` escapes or surrogates already in ``text`` can bring them (walk the data then)."""
    if _NUL_OR_SURROGATE_ESCAPE.search(text):
        return True
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


def _bad_string(data: Any, where: str = "") -> str | None:
    """A description of the first string (key or value) with a NUL or a lone surrogate."""
    stack: list[tuple[Any, str]] = [(data, where)]
    while stack:
        obj, at = stack.pop()
        if isinstance(obj, str):
            why = _string_problem(obj)
            if why:
                return f"{at or 'value'}: string {why}"
        elif isinstance(obj, dict):
            for k, v in obj.items():
                why = _string_problem(k)
                if why:
                    return f"{at or 'object'}: key {why}"
                key = printable(k)
                stack.append((v, f"{at}.{key}" if at else key))
        elif isinstance(obj, list):
            stack.extend((v, f"{at}[{i}]") for i, v in enumerate(obj))
    return None


def _string_problem(s: str) -> str | None:
    if "\x00" in s:
        return "holds a NUL character (\\u0000)"
    try:
        s.encode("utf-8")
    except UnicodeEncodeError:
        return "holds a lone surrogate (\\ud800-\\udfff)"
    return None


def check_text_field(value: str, where: str) -> str:
    """``value`` unchanged; a NUL character or lone surrogate is an :class:`InputError`."""
    why = _string_problem(value)
    if why:
        raise InputError(f"{where}: string {why}")
    return value


# ---- .npz ----------------------------------------------------------------------------------------


def read_npz(
    path: str | os.PathLike,
    *,
    what: str = "data set",
    max_elements: int = MAX_NPZ_ELEMENTS,
    max_members: int = MAX_NPZ_MEMBERS,
) -> dict[str, np.ndarray]:
    """All arrays of an ``.npz`` file, each member's header checked before its data is read.

    Refused with one line naming the file: a missing, empty or too large file, not a zip, more
    than ``max_members`` members, a member that is not a ``.npy`` array, an object (pickled)
    dtype, a member whose header claims more than ``max_elements`` elements (the running total
    over all members is bounded too), data shorter than the header claims, a bad CRC or
    corrupt compressed data.
    """
    src = str(path)
    try:
        size = os.stat(path).st_size
    except FileNotFoundError:
        raise InputError("file not found", src) from None
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read {what} ({_reason(exc)})", printable(src)) from None
    if size == 0:
        raise InputError(f"cannot read {what}: the file is empty (0 bytes)", src)
    if size > MAX_INPUT_BYTES:
        raise InputError(f"{what} is {size} bytes, more than the limit {MAX_INPUT_BYTES}", src)
    out: dict[str, np.ndarray] = {}
    total = 0
    try:
        with zipfile.ZipFile(path) as zf:
            infos = zf.infolist()
            if len(infos) > max_members:
                raise InputError(
                    f"{what} has {len(infos)} members, more than the limit {max_members}", src
                )
            for info in infos:
                name = info.filename
                key = name[:-4] if name.endswith(".npy") else name
                with zf.open(info) as fh:
                    shape, dtype, fortran = _npy_header(fh, name, src)
                    count = int(np.prod(shape, dtype=np.float64))
                    total += count
                    if count > max_elements or total > max_elements:
                        raise InputError(
                            f"array {key!r} has shape {shape} ({count} elements); {what}s are "
                            f"limited to {max_elements} elements in all",
                            src,
                        )
                    out[key] = _npy_data(fh, shape, dtype, fortran, key, src)
    except InputError:
        raise
    except (zipfile.BadZipFile, zlib.error, EOFError, NotImplementedError, RuntimeError) as exc:
        raise InputError(f"cannot read {what}: corrupt .npz ({_reason(exc)})", src) from None
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read {what} ({_reason(exc)})", src) from None
    return out


def _npy_header(fh: IO[bytes], name: str, src: str) -> tuple[tuple[int, ...], np.dtype, bool]:
    fmt = np.lib.format
    try:
        version = fmt.read_magic(fh)
        if version == (1, 0):
            shape, fortran, dtype = fmt.read_array_header_1_0(fh)
        elif version == (2, 0):
            shape, fortran, dtype = fmt.read_array_header_2_0(fh)
        else:
            raise ValueError(f"unsupported .npy version {version}")
    except (ValueError, EOFError, SyntaxError, TypeError) as exc:
        raise InputError(f"member {name!r} is not a .npy array ({_reason(exc)})", src) from None
    if dtype.hasobject:
        raise InputError(f"member {name!r} holds Python objects (pickle); refused", src)
    return tuple(int(n) for n in shape), dtype, bool(fortran)


def _npy_data(
    fh: IO[bytes], shape: tuple[int, ...], dtype: np.dtype, fortran: bool, key: str, src: str
) -> np.ndarray:
    count = int(np.prod(shape, dtype=np.int64))
    nbytes = count * dtype.itemsize
    data = fh.read(nbytes)
    if len(data) != nbytes:
        raise InputError(f"array {key!r} is truncated: {len(data)} of {nbytes} bytes", src)
    array = np.frombuffer(data, dtype=dtype, count=count)
    if fortran:
        return array.reshape(shape[::-1]).transpose().copy()
    return array.reshape(shape).copy()


def _reason(exc: BaseException) -> str:
    text = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return printable(text.splitlines()[0] if text else type(exc).__name__)


def printable(text: str) -> str:
    """``text`` as one printable line: control characters, line separators and lone surrogates
    escaped (``\\x0a``, ``\\u2028``, ``\\udc80``), so that an error naming it stays one line."""
    return text.encode("utf-8", "backslashreplace").decode("utf-8").translate(_CONTROL_ESCAPES)


_CONTROL_ESCAPES = {
    **{c: f"\\x{c:02x}" for c in (*range(0x20), *range(0x7F, 0xA0))},
    0x2028: "\\u2028",
    0x2029: "\\u2029",
}

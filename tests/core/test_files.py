"""core.files: atomic writes leave nothing half-written; untrusted JSON and .npz are refused with
one line naming the file before anything large is allocated or anything recurses."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from core.errors import InputError
from core.files import (
    atomic_open,
    parse_json,
    read_json,
    read_npz,
    read_text,
    write_json_atomic,
    write_npz_atomic,
    write_text_atomic,
)
from core.limits import MAX_JSON_DEPTH, MAX_NPZ_ELEMENTS

# ---- atomic writes -----------------------------------------------------------------------------


def test_atomic_write_replaces_and_leaves_no_temporary(tmp_path: Path) -> None:
    path = tmp_path / "sub" / "a.json"
    write_json_atomic(path, {"x": 1})
    write_json_atomic(path, {"x": 2})
    assert json.loads(path.read_text()) == {"x": 2}
    assert path.read_text().endswith("}\n")
    assert sorted(p.name for p in path.parent.iterdir()) == ["a.json"]


def test_failed_write_keeps_the_old_file_and_removes_the_temporary(tmp_path: Path) -> None:
    path = tmp_path / "a.txt"
    write_text_atomic(path, "old\n")
    with pytest.raises(RuntimeError), atomic_open(path, "w") as fh:
        fh.write("half")
        raise RuntimeError("disk full")
    assert path.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_unserialisable_json_leaves_nothing(tmp_path: Path) -> None:
    path = tmp_path / "a.json"
    with pytest.raises(TypeError):
        write_json_atomic(path, {"x": object()})
    assert list(tmp_path.iterdir()) == []


def test_npz_roundtrip(tmp_path: Path) -> None:
    a = {
        "x": np.arange(6.0).reshape(2, 3),
        "f": np.asfortranarray(np.ones((3, 2))),
        "s": np.array("t"),
    }
    write_npz_atomic(tmp_path / "a.npz", a)
    b = read_npz(tmp_path / "a.npz")
    assert set(b) == set(a)
    for k in a:
        np.testing.assert_array_equal(b[k], a[k])


# ---- JSON --------------------------------------------------------------------------------------


def test_deep_json_refused_before_recursion(tmp_path: Path) -> None:
    """1000-deep nesting: RecursionError before the fix; now one line naming the file."""
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(InputError, match=rf"deep.json:1: JSON nested deeper than {MAX_JSON_DEPTH}"):
        read_json(path)
    # brackets inside strings do not count; the limit itself is allowed
    ok = "[" * MAX_JSON_DEPTH + '"[[[[{{{{"' + "]" * MAX_JSON_DEPTH
    assert parse_json(ok, "ok") is not None


def test_latin1_byte_is_one_line_with_position(tmp_path: Path) -> None:
    path = tmp_path / "p.json"
    path.write_bytes(b'{\n "model": "caf\xe9"}')
    with pytest.raises(InputError, match=r"p.json:2: .*not UTF-8.*0xe9 at column 15"):
        read_text(path)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('{"radar": "\\u0000"}', r"radar: string holds a NUL"),
        ('{"radar": "\\ud800"}', r"radar: string holds a lone surrogate"),
        ('{"\\udfff": 1}', r"key holds a lone surrogate"),
        ('{"a": [1, NaN]}', r"NaN is not allowed"),
        ('{"a": -Infinity}', r"-Infinity is not allowed"),
        ('{"a": 1,}', r"x.json:1: invalid JSON at line 1"),
    ],
)
def test_strings_and_constants_refused(text: str, match: str) -> None:
    with pytest.raises(InputError, match=match) as err:
        parse_json(text, "x.json")
    assert "\n" not in str(err.value)


def test_missing_directory_and_nul_path_are_one_line(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not found"):
        read_json(tmp_path / "nope.json")
    with pytest.raises(InputError, match="is a directory"):
        read_json(tmp_path)
    with pytest.raises(InputError, match="cannot read"):
        read_json(str(tmp_path / "a\x00b"))


def test_size_limit(tmp_path: Path) -> None:
    path = tmp_path / "big.json"
    path.write_text("[" + "0," * 100 + "0]")
    with pytest.raises(InputError, match="more than the limit 50"):
        read_json(path, limit=50)


# ---- .npz --------------------------------------------------------------------------------------


def npz_with_member(path: Path, name: str, header: dict, data: bytes = b"") -> None:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, header)
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr(name, buf.getvalue() + data)


def test_npz_header_claiming_1e12_elements_is_refused_before_allocating(tmp_path: Path) -> None:
    """Before the fix: np.load tried to allocate 7 TiB."""
    path = tmp_path / "huge.npz"
    header = {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}
    npz_with_member(path, "frame.npy", header, b"\0" * 64)
    with pytest.raises(
        InputError, match=rf"huge.npz: array 'frame' has shape .*{MAX_NPZ_ELEMENTS}"
    ):
        read_npz(path)


def test_npz_truncated_member_and_pickle_refused(tmp_path: Path) -> None:
    path = tmp_path / "short.npz"
    npz_with_member(
        path, "a.npy", {"descr": "<f8", "fortran_order": False, "shape": (10,)}, b"\0" * 8
    )
    with pytest.raises(InputError, match="truncated: 8 of 80 bytes"):
        read_npz(path)
    path = tmp_path / "obj.npz"
    np.savez(path, a=np.array([{"x": 1}], dtype=object))
    with pytest.raises(InputError, match="pickle"):
        read_npz(path)
    path = tmp_path / "notnpy.npz"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("a.npy", b"hello")
    with pytest.raises(InputError, match="not a .npy array"):
        read_npz(path)


def test_empty_and_non_zip_npz(tmp_path: Path) -> None:
    """Before the fix: EOFError from np.load on a 0-byte file."""
    (tmp_path / "empty.npz").write_bytes(b"")
    with pytest.raises(InputError, match=r"empty.npz: .*empty \(0 bytes\)"):
        read_npz(tmp_path / "empty.npz")
    (tmp_path / "text.npz").write_text("not a zip")
    with pytest.raises(InputError, match="corrupt .npz"):
        read_npz(tmp_path / "text.npz")


def valid_npz(path: Path) -> bytes:
    write_npz_atomic(path, {"a": np.linspace(0.0, 1.0, 4000), "b": np.arange(3000)})
    return path.read_bytes()


def member_data_offset(data: bytes, name: str) -> int:
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        info = zf.getinfo(name)
    start = info.header_offset
    n_name = int.from_bytes(data[start + 26 : start + 28], "little")
    n_extra = int.from_bytes(data[start + 28 : start + 30], "little")
    return start + 30 + n_name + n_extra


def test_flipped_compressed_byte_is_corrupt_not_zlib_error(tmp_path: Path) -> None:
    """Before the fix: zlib.error / BadZipFile (bad CRC) escaped as a traceback."""
    data = bytearray(valid_npz(tmp_path / "ok.npz"))
    at = member_data_offset(bytes(data), "a.npy")
    for k in range(0, 400, 7):  # every flip is refused or (rarely) still decodes to valid data
        bad = bytearray(data)
        bad[at + k] ^= 0xFF
        (tmp_path / "bad.npz").write_bytes(bytes(bad))
        try:
            read_npz(tmp_path / "bad.npz")
        except InputError as exc:
            assert "bad.npz" in str(exc) and "\n" not in str(exc)


def test_encrypted_flag_is_refused(tmp_path: Path) -> None:
    """Flipping the 'encrypted' bit: zipfile raised RuntimeError before the fix."""
    data = bytearray(valid_npz(tmp_path / "ok.npz"))
    central = data.rfind(b"PK\x01\x02")
    while central >= 0:
        data[central + 8] |= 0x01
        central = data.rfind(b"PK\x01\x02", 0, central)
    (tmp_path / "enc.npz").write_bytes(bytes(data))
    with pytest.raises(InputError, match=r"enc.npz: cannot read data set: corrupt .npz"):
        read_npz(tmp_path / "enc.npz")


def test_key_with_line_breaks_stays_one_line() -> None:
    """Found by the long fuzz run: a key with control characters and a NUL below it."""
    with pytest.raises(InputError) as err:
        parse_json('{"a\\n\\u2028b\\r": {"c": "\\u0000"}}', "x.json")
    assert len(str(err.value).splitlines()) == 1
    assert "a\\x0a\\u2028b\\x0d.c: string holds a NUL" in str(err.value)


def test_atomic_write_gets_the_mode_a_plain_open_gives(tmp_path: Path) -> None:
    """mkstemp makes 0600 files; a written report or data set must be readable as a plain
    open() would leave it (0666 less the umask), like the files written without atomic_open."""
    import os
    import stat

    from core.files import write_text_atomic

    plain = tmp_path / "plain.txt"
    plain.write_text("x")
    write_text_atomic(tmp_path / "atomic.txt", "x")
    mode = stat.S_IMODE(os.stat(tmp_path / "atomic.txt").st_mode)
    assert mode == stat.S_IMODE(os.stat(plain).st_mode)

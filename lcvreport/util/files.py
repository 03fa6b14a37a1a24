"""The one reader of every file a user hands in: vehicle files, both tire formats, steer
tables, criteria, studies, measured tires.

A file given on the command line may be anything: a FIFO (which blocks a reader forever), a
device (``/dev/zero`` never ends), a folder, a file of gigabytes.  :func:`read_text_file`
opens without blocking, refuses everything but a regular file of at most ``max_bytes``
before it reads a byte, reads at most ``max_bytes + 1`` bytes (a file that grows meanwhile is
still refused), decodes UTF-8 (a byte-order mark, which spreadsheet programs write, is
dropped) and raises :class:`FileInputError` with one line naming the file and what is wrong.
:func:`read_csv` adds what every CSV reader needs: a header whose columns are named once,
rows with no more values than the header, the line number of each row.

Examples
--------
>>> import os, tempfile
>>> d = tempfile.mkdtemp()
>>> os.mkfifo(os.path.join(d, "pipe"))
>>> try:
...     read_text_file(os.path.join(d, "pipe"), "vehicle file")
... except FileInputError as exc:
...     print(str(exc).split("/")[-1])
pipe is a FIFO (a named pipe), not a regular file: give the vehicle file as a file
"""
from __future__ import annotations

import os
import stat
from pathlib import Path

#: the default largest file read [bytes]: 1 MiB holds a 100-unit vehicle, a criteria file, a study
MAX_BYTES = 1 << 20


class FileInputError(ValueError):
    """A file that cannot be read as the text it should be; the message is one line naming it."""


def _kind(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a FIFO (a named pipe)"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _size_text(n: int) -> str:
    return f"{n} bytes ({n / (1 << 20):.3g} MiB)" if n >= 1 << 20 else f"{n} bytes"


def read_file_bytes(path: str | Path, what: str = "file", max_bytes: int = MAX_BYTES) -> bytes:
    """The bytes of the regular file ``path`` (at most ``max_bytes``), with every refusal of
    :func:`read_text_file` but the decoding: what a report copies byte for byte (a scheme file,
    whose SHA-256 the report prints).

    Raises
    ------
    FileInputError
        A missing or unreadable file, anything but a regular file (refused without reading from
        it), a file larger than ``max_bytes``.  One line naming the file.
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise FileInputError(f"cannot read {path}: it does not exist (no {what} there)") from None
    except OSError as exc:
        raise FileInputError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise FileInputError(f"{path} is {_kind(st.st_mode)}, not a regular file: give the {what} as a file")
        if st.st_size > max_bytes:
            raise FileInputError(f"{path} has {_size_text(st.st_size)}; a {what} has at most {_size_text(max_bytes)}")
        chunks, total = [], 0
        while total <= max_bytes:
            part = os.read(fd, min(1 << 20, max_bytes + 1 - total))
            if not part:
                break
            chunks.append(part)
            total += len(part)
    except OSError as exc:
        raise FileInputError(f"cannot read {path}: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > max_bytes:
        raise FileInputError(f"{path} has more than {_size_text(max_bytes)}; a {what} has at most "
                             f"{_size_text(max_bytes)}")
    return data


def read_text_file(path: str | Path, what: str = "file", max_bytes: int = MAX_BYTES) -> str:
    """The text of the regular file ``path``: at most ``max_bytes``, UTF-8 (a leading
    byte-order mark dropped).

    Parameters
    ----------
    path : str or Path
    what : str
        What the file is, for the message (``"vehicle file"``, ``"steer table"``).
    max_bytes : int
        The largest file accepted [bytes].

    Returns
    -------
    str

    Raises
    ------
    FileInputError
        A missing or unreadable file, anything but a regular file (refused without reading
        from it, so a FIFO or a device never blocks), a file larger than ``max_bytes``,
        text that is not UTF-8.  One line naming the file.
    """
    data = read_file_bytes(path, what, max_bytes)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FileInputError(f"{path} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    return text[1:] if text.startswith("\ufeff") else text


def read_csv(path: str | Path, what: str, columns: tuple[str, ...], optional: tuple[str, ...] = (),
             max_bytes: int = MAX_BYTES) -> list[tuple[int, dict]]:
    """The rows of a CSV file with a header: ``[(line number, {column: text}), ...]``.

    Every column of ``columns`` must be in the header, every header name must be one of
    ``columns + optional`` and appear once, no row may have more values than the header;
    blank lines are skipped; a missing trailing value reads as ``""``.

    Raises
    ------
    FileInputError
        As :func:`read_text_file`, and for a header or row that breaks the rules above
        (naming the column or the line).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> _ = p.write_text("\\ufeffid,x\\nA,1\\n\\nB,2\\n", encoding="utf-8")
    >>> read_csv(p, "table", ("id", "x"))
    [(2, {'id': 'A', 'x': '1'}), (4, {'id': 'B', 'x': '2'})]
    """
    import csv
    text = read_text_file(path, what, max_bytes)
    try:
        rows = list(csv.reader(text.splitlines()))
    except csv.Error as exc:
        raise FileInputError(f"{path}: not a CSV file ({exc})") from None
    if not rows:
        raise FileInputError(f"{path}: empty; the first line must be the header {','.join(columns)}")
    header = [c.strip() for c in rows[0]]
    valid = ", ".join(columns + optional)
    seen = set()
    for name in header:
        if name in seen:
            raise FileInputError(f"{path}: the header names column {name!r} twice; columns: {valid}")
        seen.add(name)
        if name not in columns and name not in optional:
            raise FileInputError(f"{path}: unknown column {name!r}; columns: {valid}")
    missing = [c for c in columns if c not in seen]
    if missing:
        raise FileInputError(f"{path}: missing column {missing[0]!r}; columns: {valid}")
    out = []
    for line, row in enumerate(rows[1:], start=2):
        if not row or all(not c.strip() for c in row):
            continue
        if len(row) > len(header):
            raise FileInputError(f"{path}: line {line} has {len(row)} values, the header {len(header)} columns")
        out.append((line, {name: (row[k] if k < len(row) else "") for k, name in enumerate(header)}))
    return out


class TomlNumberError(ValueError):
    """What tomllib cannot say in one line: a TOML number Python cannot convert (an integer of
    thousands of digits), a key of thousands of dotted parts, nesting that exhausts the stack --
    with its line and key where there is one."""


#: the most dotted parts a key of a user's TOML file may have (tomllib takes time quadratic in them:
#: a 40,000-part key would hang it); no file of the toolkit needs more than 4
MAX_KEY_PARTS = 32


def _code_of(text: str) -> str:
    """``text`` with every string literal replaced by ``S`` and every comment removed (line breaks
    kept): what remains are keys, values and punctuation -- so that a period in a comment or a
    quoted string is not read as a key's dot."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if c in "\"'":
            triple = text.startswith(c * 3, i)
            end, i = (c * 3 if triple else c), i + (3 if triple else 1)
            while i < n:
                if c == '"' and text[i] == "\\":
                    i += 2
                    continue
                if text.startswith(end, i):
                    i += len(end)
                    break
                if not triple and text[i] == "\n":
                    break
                if text[i] == "\n":
                    out.append("\n")
                i += 1
            out.append("S")
            continue
        out.append(c)
        i += 1
    return "".join(out)


def check_key_parts(text: str, limit: int = MAX_KEY_PARTS) -> tuple[int, int] | None:
    r"""(line, parts) of the first key of more than ``limit`` dotted parts in a TOML text, or None;
    keys in table headers, on the left of ``=``, and in inline tables -- not periods in comments,
    strings or numbers.

    Examples
    --------
    >>> check_key_parts("# loads [t]: 5.4. 8.1. 7.9. 7.9. 8.2. 8.0. 7.7. 7.8. 8.3. 8.1. 7.9. 8.0. 8.2. 7.9. 8.1. 8.0.\nx = 1.5")
    >>> check_key_parts("a" + ".a" * 40 + " = 1")
    (1, 41)
    """
    import re
    code = _code_of(text)
    keys = re.finditer(r"(?m)^[ \t]*\[\[?([^\]\n]*)\]|(?:^|[{,])[ \t]*([^=\[\]{},\n]*?)[ \t]*=", code)
    for m in keys:
        key = m.group(1) if m.group(1) is not None else m.group(2)
        if key.count(".") >= limit:
            return code.count("\n", 0, m.start()) + 1, key.count(".") + 1
    return None


def loads_toml(text: str) -> dict:
    """:func:`tomllib.loads`, saying in one line what tomllib cannot: an integer literal too long
    to convert (Python's digit limit) is named by its line and key (:class:`TomlNumberError`).

    Raises
    ------
    tomllib.TOMLDecodeError
        Not valid TOML.
    TomlNumberError
        An integer of more digits than Python converts.

    Examples
    --------
    >>> loads_toml("mass_kg = " + "9" * 5000)
    Traceback (most recent call last):
    ...
    lcvreport.util.files.TomlNumberError: line 1: mass_kg is an integer of 5000 digits; a number here has a physical size
    """
    import re
    import tomllib
    long_key = check_key_parts(text)
    if long_key is not None:
        raise TomlNumberError(f"line {long_key[0]}: a key of {long_key[1]} dotted parts; a file of the toolkit needs "
                              "at most 4")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        raise
    except (RecursionError, MemoryError):
        raise TomlNumberError("not readable: its TOML nests too deeply (a file of the toolkit nests its tables "
                              "and arrays 4 deep)") from None
    except ValueError as exc:
        m = re.search(r"[0-9_]{1000,}", text)
        if m is None:
            raise TomlNumberError(f"not valid TOML: {str(exc).split(';')[0]}") from None
        line_no = text.count("\n", 0, m.start()) + 1
        head = text[text.rfind("\n", 0, m.start()) + 1:m.start()]
        key = re.search(r"([A-Za-z0-9_.\"'-]+)\s*=\s*[-+]?$", head)
        digits = len(m.group(0).replace("_", ""))
        raise TomlNumberError(f"line {line_no}: {key.group(1) if key else 'a value'} is an integer of {digits} "
                              "digits; a number here has a physical size") from None


def read_toml_file(path: str | Path, what: str = "file", max_bytes: int = MAX_BYTES) -> dict:
    """A user's TOML file through :func:`read_text_file` and :func:`loads_toml`: every refusal
    -- the file itself, its TOML, an integer of thousands of digits -- one
    :class:`FileInputError` naming ``what`` and the file.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.NamedTemporaryFile("w", suffix=".toml", delete=False) as f:
    ...     _ = f.write("speed_kph = [")
    >>> try:
    ...     read_toml_file(f.name, "study file")
    ... except FileInputError as exc:
    ...     print(str(exc).split(":")[0].endswith("is not valid TOML"))
    True
    >>> os.unlink(f.name)
    """
    import tomllib
    text = read_text_file(path, what, max_bytes)
    try:
        return loads_toml(text)
    except tomllib.TOMLDecodeError as exc:
        raise FileInputError(f"{what} {path} is not valid TOML: {exc}") from None
    except TomlNumberError as exc:
        raise FileInputError(f"{what} {path}: {exc}") from None

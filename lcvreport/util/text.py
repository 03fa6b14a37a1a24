"""Text a user wrote that the toolkit prints, writes into reports, XML or C: what may be in it.

A scheme's name, its levels and sources, a vehicle's description reach a terminal (where an ESC
or OSC sequence is a command), a verdict table (where a newline forges a line), a report and a
LaTeX run (where U+0000 stops xelatex).  :func:`control_character` finds what must be refused.

Examples
--------
>>> control_character("L1"), control_character("L1\\x1b]0;x\\x07")
(None, '\\x1b')
>>> control_character("two\\nlines", allow="\\n")
"""
from __future__ import annotations

import unicodedata

#: Unicode categories never accepted in a user's text: controls, surrogates, private use, unassigned
REFUSED_CATEGORIES = ("Cc", "Cs", "Co", "Cn")
#: the bidirectional overrides and isolates, which reorder what a reader sees (U+202A-U+202E,
#: U+2066-U+2069)
BIDI_CONTROLS = frozenset("\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")


def control_character(text: str, allow: str = "") -> str | None:
    """The first character of ``text`` a user's text may not hold (a control character, a
    surrogate, a private-use or unassigned code point, a bidirectional override), or None;
    characters in ``allow`` (a line break in a free description) are accepted.

    Parameters
    ----------
    text : str
    allow : str
        Characters accepted although they are controls (``"\\n\\t"``).

    Returns
    -------
    str or None
    """
    for ch in text:
        if ch in allow:
            continue
        if unicodedata.category(ch) in REFUSED_CATEGORIES or ch in BIDI_CONTROLS:
            return ch
    return None


def named(text: str) -> str:
    """A key or level name as a message names it: as written when it is plain (printable, no
    space, no quote), else :func:`shown` (quoted, escaped).

    Examples
    --------
    >>> named("L1"), named("level one")
    ('L1', '"level one"')
    """
    plain = text and not any(ch.isspace() or ch in "\"'" for ch in text) and control_character(text) is None
    return text if plain and len(text) <= 60 else shown(text)


def listed(items, limit: int = 8, what: str = "") -> str:
    """Names for a message: all of them when few, else the first ``limit`` and how many there are
    (ten thousand levels are not one line's worth).

    Examples
    --------
    >>> listed(["L1", "L2"]), listed([f"L{k}" for k in range(100)], 3, "levels")
    ('L1, L2', 'L0, L1, L2, ... (100 levels)')
    """
    items = [str(x) for x in items]
    if len(items) <= limit:
        return ", ".join(items)
    return ", ".join(items[:limit]) + f", ... ({len(items)}{' ' + what if what else ''})"


def shown(text: str, limit: int = 60) -> str:
    """``text`` as a one-line message shows it: quoted, control characters escaped, at most
    ``limit`` characters (an ellipsis marks the cut).

    Examples
    --------
    >>> shown("a\\nb")
    '"a\\\\nb"'
    """
    import json
    cut = text if len(text) <= limit else text[:limit] + "…"
    return json.dumps(cut, ensure_ascii=False)

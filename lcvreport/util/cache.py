"""A small least-recently-used cache (discretizations, eigenvalues per speed)."""
from __future__ import annotations

from collections import OrderedDict
from typing import Callable, Hashable, TypeVar

T = TypeVar("T")


class LRUCache:
    """``get(key, compute)`` returns the cached value or stores ``compute()``.

    At most ``maxsize`` entries are kept; the least recently used goes first.

    Examples
    --------
    >>> c = LRUCache(2)
    >>> c.get("a", lambda: 1), c.get("a", lambda: 2), len(c)
    (1, 1, 1)
    """

    def __init__(self, maxsize: int = 64):
        self.maxsize = int(maxsize)
        self._data: OrderedDict = OrderedDict()

    def get(self, key: Hashable, compute: Callable[[], T]) -> T:
        """The value for ``key``, computed by ``compute()`` on a miss."""
        if key in self._data:
            self._data.move_to_end(key)
            return self._data[key]
        value = compute()
        self._data[key] = value
        if len(self._data) > self.maxsize:
            self._data.popitem(last=False)
        return value

    def clear(self) -> None:
        """Drop every entry."""
        self._data.clear()

    def __len__(self) -> int:
        return len(self._data)

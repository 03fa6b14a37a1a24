"""Small least-recently-used caches: :class:`LRUCache` (discretizations, eigenvalues per speed)
and :func:`memoized`, a function's results per arguments (the low-speed turn and the turn with
tire forces, computed once per vehicle and conditions however many measures, evidence figures
and reports read them)."""
from __future__ import annotations

import functools
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

    def __contains__(self, key: Hashable) -> bool:
        """Whether ``key`` is cached (without counting as a use)."""
        return key in self._data


def memoized(maxsize: int = 32):
    """A decorator: ``functools.lru_cache(maxsize)`` over the function, used only when every
    argument hashes -- a bad argument still reaches the function's own one-line refusal, never
    a ``TypeError: unhashable``; ``.cache_clear()`` and ``.cache_info()`` as lru_cache's.

    Examples
    --------
    >>> calls = []
    >>> @memoized(4)
    ... def size(x):
    ...     calls.append(x)
    ...     return len(x)
    >>> size("ab"), size("ab"), size(["a", "b", "c"]), len(calls)    # a list: computed, not kept
    (2, 2, 3, 2)
    """
    def wrap(fn):
        cached = functools.lru_cache(maxsize=maxsize)(fn)

        @functools.wraps(fn)
        def call(*args, **kwargs):
            try:
                hash((args, tuple(sorted(kwargs.items()))))
            except TypeError:
                return fn(*args, **kwargs)
            return cached(*args, **kwargs)
        call.cache_clear, call.cache_info = cached.cache_clear, cached.cache_info
        return call
    return wrap

"""The beliefs of one predicate, indexed by argument value, by key and by numeric order.

A :class:`Relation` holds the argument tuples of every belief ``name(a1, ..., an)``:

- ``rows``: the argument tuples, as the keys of a dict (membership of a ground belief in O(1), and
  iteration in the order the beliefs were added, so answers never depend on string hashing);
- ``by_pos[p]``: for each position, value -> the rows with that value there (the
  row itself while it is the only one, a dict of rows from the second on);
- ``by_key``: for mutually exclusive predicates of two or more arguments, the key
  (all arguments but the last) -> the one row holding it (section 5.1);
- ``ordered[p]``: built the first time a range is asked of position ``p``, the
  distinct numeric values there, sorted, and kept up to date afterwards;
- ``journal``: for a relation rules read, the rows added and removed since the rules last looked
  (:class:`Journal`), so derived beliefs follow by their differences.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from itertools import count
from operator import itemgetter

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

    from sortedcontainers import SortedList


#: Most distinct values at a position whose values in a range are counted one by one rather than in an ordered index
FEW_VALUES = 64


def is_number(value: Any) -> bool:
    kind = type(value)
    return kind is int or kind is float


class Relation:
    """Indexed storage of one predicate's beliefs (a name and an arity)."""

    __slots__ = ("_columns", "_projections", "arity", "by_key", "by_pos", "journal", "name", "ordered", "rows",
                 "version")

    def __init__(self, name: str, arity: int, exclusive: bool, lazy: bool = False) -> None:
        self.name = name
        self.arity = arity
        self.rows: dict[tuple, None] = {}
        # a derived relation indexes a position the first time it is asked of it (_Indexes)
        self.by_pos: list[dict[Any, Any]] = _Indexes(self, arity) if lazy else [{} for _ in range(arity)]
        self.by_key: dict[tuple, tuple] | None = {} if exclusive and arity >= 2 else None
        self.ordered: dict[int, SortedList] = {}
        self.version = 0
        self.journal: Journal | None = None
        self._projections: dict[tuple, list] = {}
        self._columns: dict[tuple, tuple[int, dict, int]] = {}

    def __len__(self) -> int:
        return len(self.rows)

    def insert(self, args: tuple) -> tuple | None:
        """Store a row; returns the row its key displaced (an exclusive relation's), else None, or :data:`PRESENT`
        when the row was stored already (then nothing changes). A load stores every row through here: the row is
        hashed once to be stored and found present, and filed in each position's index inline."""
        rows = self.rows
        size = len(rows)
        rows[args] = None
        if len(rows) == size:
            return PRESENT
        displaced = None
        by_key = self.by_key
        if by_key is not None:
            key = args[:-1]
            displaced = by_key.setdefault(key, args)  # a new key is filed with one look-up
            if displaced is args:
                displaced = None
            elif not self.ordered:
                return self._replace(displaced, args, key)
            else:
                self.delete(displaced)
                by_key[key] = args
        for index, value in zip(self.by_pos, args):  # noqa: B905 (a row has the arity of its relation)
            bucket = index.setdefault(value, args)  # _index, inlined: a new value is filed with one look-up
            if bucket is not args:
                if type(bucket) is dict:
                    bucket[args] = None
                else:
                    index[value] = {bucket: None, args: None}
        if self.ordered:
            for p, values in self.ordered.items():
                value = args[p]
                if is_number(value) and self.by_pos[p][value] is args:  # a value new here
                    values.add(value)
        self.version += 1
        if self.journal is not None:
            self.journal.inserted(args)
        return displaced

    def _replace(self, old: tuple, new: tuple, key: tuple) -> tuple:
        """``new`` (stored already in :attr:`rows`) takes the place of ``old``, whose key it has: the indexes of the
        key's places swap one row for the other where it is filed; the last place's moves. As :meth:`delete` then
        filing ``new``, in fewer steps (a position updated every tick replaces its row so)."""
        del self.rows[old]
        self.by_key[key] = new  # type: ignore[index]
        by_pos = self.by_pos
        last = len(new) - 1
        for p in range(last):
            index = by_pos[p]
            value = new[p]
            bucket = index[value]
            if bucket is old:
                index[value] = new
            else:
                del bucket[old]
                bucket[new] = None
        index = by_pos[last]
        value = old[last]
        bucket = index[value]
        if type(bucket) is dict:
            del bucket[old]
            if len(bucket) == 1:
                index[value] = next(iter(bucket))
        else:
            del index[value]
        value = new[last]
        bucket = index.setdefault(value, new)
        if bucket is not new:
            if type(bucket) is dict:
                bucket[new] = None
            else:
                index[value] = {bucket: None, new: None}
        self.version += 2  # a row removed, a row added
        if self.journal is not None:
            self.journal.deleted(old)
            self.journal.inserted(new)
        return old

    def insert_new(self, rows: Iterable[tuple]) -> None:
        """Store rows known not to be stored yet, in bulk (a derived relation: neither exclusive nor journaled)."""
        stored = self.rows
        by_pos = self.by_pos
        built = [(p, index) for p, index in enumerate(by_pos) if index is not None]
        if not built and not self.ordered:
            stored.update(rows if type(rows) is dict else dict.fromkeys(rows))  # a dict of rows: its keys, as they are
            self.version += 1
            return
        for args in rows:
            stored[args] = None
            for p, index in built:
                _index(index, args[p], args)
            if self.ordered:
                for p, values in self.ordered.items():
                    value = args[p]
                    if is_number(value) and by_pos[p][value] is args:
                        values.add(value)
        self.version += 1

    def delete(self, args: tuple) -> None:
        """Forget a stored row."""
        self.rows.pop(args, None)
        for p, (index, value) in enumerate(zip(self.by_pos, args)):  # noqa: B905
            if index is None:  # not built yet (a derived relation)
                continue
            bucket = index[value]
            if type(bucket) is dict:
                bucket.pop(args, None)
                if len(bucket) == 1:
                    index[value] = next(iter(bucket))
            else:
                del index[value]
                if self.ordered and p in self.ordered and is_number(value):
                    self.ordered[p].remove(value)
        if self.by_key is not None and self.by_key.get(args[:-1]) == args:
            del self.by_key[args[:-1]]
        self.version += 1
        if self.journal is not None:
            self.journal.deleted(args)

    def bucket(self, position: int, value: Any) -> Any:
        """Rows whose argument at ``position`` equals ``value`` (may be empty)."""
        bucket = self.by_pos[position].get(value)
        if bucket is None:
            return _EMPTY
        return bucket if type(bucket) is dict else (bucket,)

    def average_bucket(self, position: int) -> float:
        """Expected rows per value at ``position``: the planner's guess for an unknown value (a derived relation
        whose index of ``position`` is not built guesses the square root of its size rather than build one that
        every row it derives would then be filed in)."""
        by_pos = self.by_pos
        if type(by_pos) is _Indexes and list.__getitem__(by_pos, position) is None:
            return len(self.rows) ** 0.5
        distinct = len(by_pos[position])
        return len(self.rows) / distinct if distinct else 0.0

    def _ordered(self, position: int) -> SortedList:
        index = self.ordered.get(position)
        if index is None:
            from sortedcontainers import SortedList  # here: only a range or order over a position needs one

            index = SortedList(v for v in self.by_pos[position] if is_number(v))
            self.ordered[position] = index
        return index

    def count_in_range(self, position: int, low: Any, high: Any, inclusive: tuple) -> int:
        """How many distinct numeric values at ``position`` lie in the range (a position of a few values without an
        ordered index is counted value by value: a planner's estimate builds no index, nor imports one)."""
        index = self.ordered.get(position)
        if index is None and len(self.by_pos[position]) <= FEW_VALUES:
            return sum(1 for v in self.by_pos[position] if is_number(v)
                       and (low is None or (v >= low if inclusive[0] else v > low))
                       and (high is None or (v <= high if inclusive[1] else v < high)))
        index = self._ordered(position)
        lo = 0 if low is None else (
            index.bisect_left(low) if inclusive[0] else index.bisect_right(low)
        )
        hi = len(index) if high is None else (
            index.bisect_right(high) if inclusive[1] else index.bisect_left(high)
        )
        return max(0, hi - lo)

    def rows_in_range(self, position: int, low: Any, high: Any, inclusive: tuple) -> Iterator:
        """Rows whose numeric value at ``position`` lies in the range, from the ordered index."""
        index = self._ordered(position)
        for value in list(index.irange(low, high, inclusive)):
            yield from list(self.bucket(position, value))

    def projection(self, constants: tuple, position: int) -> dict:
        """The values at ``position`` of rows matching ``constants`` ((pos, value) pairs): a dict from each value
        to its rank in insertion order.

        Cached until the relation changes, so repeated joins intersect at C speed and sort only the answers.
        """
        cached = self._projected(constants, position)
        ranks = cached[2]
        if ranks is None:
            ranks = cached[2] = dict(zip(dict.fromkeys(map(itemgetter(position), self._matching(constants))),
                                         count()))
        return ranks

    def projection_set(self, constants: tuple, position: int) -> frozenset:
        """The values of :meth:`projection` as a set, cached as it is: sets intersect by the hashes they keep,
        about twice as fast as a dict's keys do."""
        return self._projected(constants, position)[1]

    def _projected(self, constants: tuple, position: int) -> list:
        """The cache entry of a projection: [version, its set of values, its ranks (None until asked)]."""
        key = (constants, position)
        cached = self._projections.get(key)
        if cached is not None and cached[0] == self.version:
            return cached
        cached = [self.version, frozenset(map(itemgetter(position), self._matching(constants))), None]
        if len(self._projections) > 256:
            self._projections.clear()
        self._projections[key] = cached
        return cached

    def _matching(self, constants: tuple) -> Iterable[tuple]:
        """The rows holding ``constants`` ((pos, value) pairs), in insertion order."""
        if not constants:
            return self.rows
        rows: Iterable[tuple] = min((self.bucket(p, v) for p, v in constants), key=len)
        if len(constants) > 1:
            rows = [r for r in rows if all(r[p] == v for p, v in constants)]
        return rows

    def columns_ready(self, position: int, taken: tuple[int, ...]) -> bool:
        """Whether :meth:`columns` of these arguments is built and current (asking it costs a look-up)."""
        cached = self._columns.get((position, taken))
        return cached is not None and cached[0] == self.version

    def columns(self, position: int, taken: tuple[int, ...]) -> tuple[dict, int]:
        """The values at the places ``taken`` of the rows, by their value at ``position`` (value -> list of
        tuples), and the longest such list: a join reads it with one look-up per row, at C speed. Built from the
        rows, kept until the relation changes."""
        key = (position, taken)
        cached = self._columns.get(key)
        if cached is not None and cached[0] == self.version:
            return cached[1], cached[2]
        table: dict[Any, list[tuple]] = {}
        get = table.get
        if taken == tuple(range(self.arity)):
            for row in self.rows:
                value = row[position]
                found = get(value)
                if found is None:
                    table[value] = [row]
                else:
                    found.append(row)
        else:
            part_of = itemgetter(*taken) if len(taken) > 1 else None
            only = taken[0] if len(taken) == 1 else None
            for row in self.rows:
                value = row[position]
                part = (row[only],) if part_of is None else part_of(row)
                found = get(value)
                if found is None:
                    table[value] = [part]
                else:
                    found.append(part)
        widest = max(map(len, table.values()), default=0)
        if len(self._columns) > 16:
            self._columns.clear()
        self._columns[key] = (self.version, table, widest)
        return table, widest


class _Indexes(list):
    """The per-position indexes of a derived relation, each built from the rows the first time it is asked."""

    __slots__ = ("relation",)

    def __init__(self, relation: Relation, arity: int) -> None:
        super().__init__([None] * arity)
        self.relation = relation

    def __getitem__(self, position):  # type: ignore[override]
        index = list.__getitem__(self, position)
        if index is None:
            index = {}
            for args in self.relation.rows:
                _index(index, args[position], args)
            list.__setitem__(self, position, index)
        return index


def _index(index: dict, value: Any, args: tuple) -> None:
    """File ``args`` under ``value`` in a position's index (the row alone, then a dict of rows from the second)."""
    bucket = index.get(value)
    if bucket is None:
        index[value] = args
    elif type(bucket) is dict:
        bucket[args] = None
    else:
        index[value] = {bucket: None, args: None}


class Journal:
    """The net change of a relation since it was last read: rows added and rows removed (an add then a remove
    of one row cancel), so its size stays bounded by the relation's, however long nobody reads it."""

    __slots__ = ("added", "removed")

    def __init__(self) -> None:
        self.added: dict[tuple, None] = {}
        self.removed: dict[tuple, None] = {}

    def inserted(self, args: tuple) -> None:
        if args in self.removed:
            del self.removed[args]
        else:
            self.added[args] = None

    def deleted(self, args: tuple) -> None:
        if args in self.added:
            del self.added[args]
        else:
            self.removed[args] = None

    def take(self) -> tuple[dict, dict]:
        """The rows added and removed since the last ``take``."""
        added, removed = self.added, self.removed
        self.added, self.removed = {}, {}
        return added, removed


class Relations(dict):
    """The memory's relations by (name, arity), with an ``epoch`` that moves whenever one
    is created or its size crosses a power of two: cached query plans are keyed on it."""

    epoch: int = 0

    def resized(self, rel: Relation) -> None:
        size = len(rel.rows)
        if not size & (size - 1):
            self.epoch += 1


_EMPTY: tuple = ()
#: what :meth:`Relation.insert` returns for a row stored already
PRESENT: tuple = ("(present)",)

"""Named layouts of packed ``float64`` vectors: one description gives offsets, views and docs.

Compiled code passes its data in a few flat vectors per row (the dynamics state, the simulator's
context, the flight conditions, the task parameters, the observation, ...). Each of them is described
once, here or in the module that owns it, by a :class:`Packed` layout: an ordered list of
:class:`Field` entries with a name, a size, a unit and a meaning. Everything else takes its indices
from that description:

- compiled kernels read the offsets from the layout's :attr:`Packed.at` namedtuple, a module global
  that numba freezes into the machine code (``c[CTX.gimbal + 1]``: the second entry of ``gimbal``);
- Python code reads and writes by name (:meth:`Packed.view`, :meth:`Packed.slice`);
- docstrings print :meth:`Packed.table`, so a table in the docs is the layout itself.

Layouts whose sizes depend on the number of bending modes per plane ``K`` and of slosh pendulums
``N`` (the dynamics state and parameters) are :class:`Linear` layouts: each field's size is
``const + per_mode K + per_slosh N`` and each offset is such a linear form, which compiled code
evaluates with :func:`at` (``at(X.eta_dot, K, N)``; a form may also have a ``K N`` term); :meth:`Linear.resolve` gives the
:class:`Packed` layout of one ``(K, N)``.

Padding. With ``LVGYM_LAYOUT_PADDING=1`` in the environment at import, every internal layout puts an
unused entry in front of each field (layouts of an interface, such as the observation, are left as
they are). A kernel that computes an offset by hand instead of taking it from its layout then reads
the wrong entry, and the test that flies the same episodes with and without padding sees it.
"""

from __future__ import annotations

import os
from collections import namedtuple
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np

__all__ = ["Field", "Linear", "LinearField", "Packed", "PADDING", "at", "at_py", "is_offsets", "offsets_layout", "rst_table"]

#: whether internal layouts are padded (see the module docstring; a test switch, read once at import)
PADDING = os.environ.get("LVGYM_LAYOUT_PADDING", "") not in ("", "0")
#: every offset namedtuple a layout made (``.at``, ``.fixed``, ``.per_slosh``): what a kernel may index with
_OFFSET_TUPLES: list[tuple] = []


def is_offsets(obj: Any) -> bool:
    """Whether ``obj`` is an offsets namedtuple of a layout (a kernel's allowed source of indices)."""
    return any(obj is t for t in _OFFSET_TUPLES)


def offsets_layout(obj: Any) -> Any:
    """The layout (:class:`Packed` or :class:`Linear`) whose offsets namedtuple ``obj`` is, or None."""
    for t, lay in zip(_OFFSET_TUPLES, _LAYOUTS):
        if obj is t:
            return lay
    return None


_LAYOUTS: list[Any] = []


def _register(offsets: tuple, layout: Any) -> tuple:
    _OFFSET_TUPLES.append(offsets)
    _LAYOUTS.append(layout)
    return offsets


@dataclass(frozen=True)
class Field:
    """One named entry of a packed vector: ``size`` numbers in ``unit``, viewed with ``shape``
    (default ``(size,)``; ``()`` for a scalar read as a number)."""

    name: str
    size: int = 1
    unit: str = "-"
    doc: str = ""
    shape: tuple[int, ...] | None = None
    #: the entries' own layout (a block written by another module's kernel); its names are reachable
    #: from the parent layout, which then owns them too
    sub: Packed | None = None

    def __post_init__(self) -> None:
        if not self.name.isidentifier() or self.name.startswith("_"):
            raise ValueError(f"field name {self.name!r}: a Python identifier not starting with '_'")
        if self.sub is not None and self.sub.size != self.size:
            raise ValueError(f"field {self.name!r}: size {self.size} but its layout {self.sub.title!r} has "
                             f"{self.sub.size} entries")
        if not isinstance(self.size, (int, np.integer)) or self.size < 0:
            raise ValueError(f"field {self.name!r}: size = {self.size!r} must be an integer >= 0")
        if self.shape is not None and int(np.prod(self.shape)) != self.size:
            raise ValueError(f"field {self.name!r}: shape {self.shape} does not hold {self.size} entries")


def _fields(entries: Iterable[Field | tuple]) -> tuple[Field, ...]:
    out = tuple(e if isinstance(e, Field) else Field(*e) for e in entries)
    names = [f.name for f in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"duplicate field names {dup}")
    return out


class Packed:
    """Fields packed end to end in one vector of :attr:`size` entries (see the module docstring).

    ``title`` names the vector in errors and tables; ``interface=True`` marks a layout that users,
    saved models or another module's kernel depend on (never padded). A field with a ``sub`` layout
    makes that layout's entries reachable by their own names (``CONDITIONS.offset("density")``)."""

    def __init__(self, title: str, fields: Sequence[Field | tuple], *, interface: bool = False,
                 pad: bool | None = None) -> None:
        self.title = title
        self.fields = _fields(fields)
        self.interface = bool(interface)
        self.padded = (PADDING if pad is None else bool(pad)) and not self.interface
        entries: dict[str, tuple[int, Field]] = {}
        o = 0
        for f in self.fields:
            o += 1 if self.padded else 0
            entries[f.name] = (o, f)
            if f.sub is not None:
                for name in f.sub.names:
                    if name in entries or name in (g.name for g in self.fields):
                        raise ValueError(f"{title}: entry {name!r} of {f.sub.title!r} clashes with another entry")
                    entries[name] = (o + f.sub.offset(name), f.sub.field(name))
            o += f.size
        self.size = o
        self._entries = entries
        self._views: dict[str, tuple[slice, tuple[int, ...] | None]] = {}     # name -> (slice, shape), on first use
        self.at = _register(namedtuple(_tuple_name(title), list(entries))(*(e[0] for e in entries.values())), self)

    # ------------------------------------------------------------------ look-up
    def __len__(self) -> int:
        return self.size

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __repr__(self) -> str:
        return f"Packed({self.title!r}, {len(self.fields)} fields, size {self.size})"

    @property
    def names(self) -> tuple[str, ...]:
        """Every entry's name: the fields and the entries of their ``sub`` layouts."""
        return tuple(self._entries)

    def leaves(self) -> list[tuple[int, Field]]:
        """``(offset, field)`` of every field, a field with a ``sub`` layout replaced by its entries."""
        out = []
        for f in self.fields:
            o = self._entries[f.name][0]
            out += [(o + so, sf) for so, sf in f.sub.leaves()] if f.sub is not None else [(o, f)]
        return out

    def field(self, name: str) -> Field:
        """The :class:`Field` ``name`` (a ``KeyError`` lists the names)."""
        try:
            return self._entries[name][1]
        except KeyError:
            raise KeyError(f"{self.title} has no entry {name!r}: one of {list(self._entries)}") from None

    def offset(self, name: str) -> int:
        """Index of the first entry of ``name``."""
        self.field(name)
        return self._entries[name][0]

    def slice(self, name: str) -> slice:
        """Slice of ``name``'s entries."""
        f = self.field(name)
        o = self._entries[name][0]
        return slice(o, o + f.size)

    def index(self, name: str) -> int:
        """Index of the single entry ``name`` (a ``ValueError`` for a multi-entry field)."""
        f = self.field(name)
        if f.size != 1:
            raise ValueError(f"{self.title}: {name!r} has {f.size} entries; use slice({name!r})")
        return self._entries[name][0]

    # ------------------------------------------------------------------ arrays
    def zeros(self, batch: int | None = None, dtype: Any = np.float64) -> np.ndarray:
        """A zero vector, or ``(batch, size)`` rows of them."""
        return np.zeros(self.size if batch is None else (batch, self.size), dtype=dtype)

    def view(self, array: np.ndarray, name: str) -> np.ndarray:
        """A view of ``name`` in ``array`` (``(..., size)``), in the field's shape: ``(..., *shape)``;
        a scalar field with ``shape=()`` gives ``(...)``."""
        if array.shape[-1] != self.size:
            raise ValueError(f"{self.title}: an array of shape {np.shape(array)}: expected (..., {self.size})")
        try:
            sl, shape = self._views[name]
        except KeyError:
            f = self.field(name)
            o = self._entries[name][0]
            sl, shape = self._views.setdefault(name, (slice(o, o + f.size), None if f.shape is None else tuple(f.shape)))
        part = array[..., sl]
        return part if shape is None else part.reshape(part.shape[:-1] + shape)

    def pack(self, values: dict[str, Any], batch: int | None = None) -> np.ndarray:
        """A vector (or ``batch`` rows) with the named ``values`` broadcast into their fields, zeros
        elsewhere."""
        out = self.zeros(batch)
        for name, value in values.items():
            out[..., self.slice(name)] = value
        return out

    def table(self, columns: Sequence[str] = ("index", "name", "unit", "meaning"),
              names: Iterable[str] | None = None) -> str:
        """A reStructuredText simple table of the layout (or of the fields ``names``)."""
        pick = self.leaves() if names is None else [(self.offset(n), self.field(n)) for n in names]
        rows = []
        for o, f in pick:
            index = str(o) if f.size == 1 else f"{o}-{o + f.size - 1}" if f.size else "-"
            cells = {"index": index, "name": f"``{f.name}``", "size": str(f.size), "unit": f.unit,
                     "meaning": f.doc}
            rows.append([cells[c] for c in columns])
        return rst_table(list(columns), rows)


def _tuple_name(title: str) -> str:
    words = "".join(ch if ch.isalnum() else " " for ch in title).split()
    return "".join(w[:1].upper() + w[1:] for w in words) + "Offsets" if words else "Offsets"


def rst_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A reStructuredText simple table (the last column may be long: it is not padded)."""
    widths = [max([len(h)] + [len(r[i]) for r in rows]) for i, h in enumerate(header)]
    rule = "  ".join("=" * w for w in widths)

    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()

    return "\n".join([rule, line(header), rule, *[line(r) for r in rows], rule])


# ---------------------------------------------------------------------------- K- and N-dependent layouts
@dataclass(frozen=True)
class LinearField:
    """A field whose size is ``const + per_mode K + per_slosh N + per_both K N`` (see :class:`Linear`);
    ``shape`` gives the viewed shape as a function of ``(K, N)`` (default: flat)."""

    name: str
    const: int = 0
    per_mode: int = 0
    per_slosh: int = 0
    per_both: int = 0
    unit: str = "-"
    doc: str = ""
    shape: Any = None

    def size(self, K: int, N: int) -> int:
        return self.const + self.per_mode * K + self.per_slosh * N + self.per_both * K * N


class Linear:
    """A layout whose field sizes, and so offsets, depend on the number of bending modes per plane ``K``
    and of slosh pendulums ``N``: each offset is a form ``(const, per_mode, per_slosh, per_both)``
    worth ``const + per_mode K + per_slosh N + per_both K N``.

    :attr:`at` is a namedtuple of those forms, for compiled code (``at(X.eta_dot, K, N)``);
    :attr:`fixed` the offsets that depend on neither, as plain integers; :attr:`per_slosh` each field's
    entries per pendulum (the stride from one pendulum to the next in a per-pendulum field);
    :meth:`resolve` the :class:`Packed` layout of one ``(K, N)``."""

    def __init__(self, title: str, fields: Sequence[LinearField], *, pad: bool | None = None) -> None:
        self.title = title
        self.fields = tuple(fields)
        names = [f.name for f in self.fields]
        if len(set(names)) != len(names):
            raise ValueError(f"{title}: duplicate field names")
        self.padded = PADDING if pad is None else bool(pad)
        forms: dict[str, tuple[int, int, int, int]] = {}
        a = b = c = d = 0
        for f in self.fields:
            a += 1 if self.padded else 0
            forms[f.name] = (a, b, c, d)
            a, b, c, d = a + f.const, b + f.per_mode, c + f.per_slosh, d + f.per_both
        self.size_form = (a, b, c, d)
        self._forms = forms
        tname = _tuple_name(title)
        self.at = _register(namedtuple(tname, names)(*forms.values()), self)
        fixed = [n for n, (_, pb, pc, pd) in forms.items() if pb == pc == pd == 0]
        self.fixed = _register(namedtuple(tname + "Fixed", fixed)(*(forms[n][0] for n in fixed)), self)
        self.per_slosh = _register(namedtuple(tname + "PerSlosh", names)(*(f.per_slosh for f in self.fields)), self)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fields)

    def form(self, name: str) -> tuple[int, int, int, int]:
        """The offset form of ``name``."""
        if name not in self._forms:
            raise KeyError(f"{self.title} has no entry {name!r}: one of {list(self._forms)}")
        return self._forms[name]

    def size(self, K: int, N: int) -> int:
        """Length of the vector for ``K`` modes per plane and ``N`` pendulums."""
        return at_py(self.size_form, K, N)

    def resolve(self, K: int, N: int) -> Packed:
        """The :class:`Packed` layout for ``K`` modes per plane and ``N`` pendulums (same offsets)."""
        fields = []
        for f in self.fields:
            shape = f.shape(K, N) if callable(f.shape) else f.shape
            fields.append(Field(f.name, f.size(K, N), f.unit, f.doc, shape))
        packed = Packed(self.title, fields, pad=self.padded)
        for f in self.fields:
            if packed.offset(f.name) != at_py(self._forms[f.name], K, N):
                raise AssertionError(f"{self.title}: offsets of {f.name!r} disagree")
        return packed

    def table_size(self) -> str:
        """The vector's length in K and N, in words (``13 + 4K + 6N``)."""
        return _size_text(self.size_form)

    def table(self) -> str:
        """A reStructuredText table of the fields with their sizes in K and N."""
        rows = []
        for f in self.fields:
            size = _size_text((f.const, f.per_mode, f.per_slosh, f.per_both))
            rows.append([f"``{f.name}``", size, f.unit, f.doc])
        return rst_table(["name", "size", "unit", "meaning"], rows)


def _size_text(form: tuple[int, int, int, int]) -> str:
    terms = [(form[0], ""), (form[1], "K"), (form[2], "N"), (form[3], "KN")]
    text = " + ".join(f"{c if c != 1 or not s else ''}{s}" for c, s in terms if c)
    return text or "0"


def at_py(form: tuple[int, int, int, int], K: int, N: int) -> int:
    """The offset of a form ``(const, per_mode, per_slosh, per_both)`` for ``K`` modes and ``N``
    pendulums (Python)."""
    return form[0] + form[1] * K + form[2] * N + form[3] * K * N


@nb.njit(cache=True, inline="always")
def at(form, K, N):
    """The offset of a form ``(const, per_mode, per_slosh, per_both)`` for ``K`` modes per plane and
    ``N`` pendulums (compiled; the form is a frozen global, so this folds to a few integer ops)."""
    return form[0] + form[1] * K + form[2] * N + form[3] * K * N

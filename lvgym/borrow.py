"""Borrowed arrays in compiled code: views that count no references.

Numba increments and decrements the reference count of an array's memory (its meminfo) whenever compiled
code makes a view of it (a row, a slice, a reshape, a named tuple holding it) and for every array argument
of a compiled function it calls, with atomic instructions on the owner's counter. The rows of one batch
share that counter, so threads that step row ranges contend for it; even on one thread the simulator's
step made several hundred such updates per row and control period. A view with a null meminfo (what
:func:`unowned` makes) turns every such update into a test of a null pointer, and so does every view made
from it. :func:`unowned_all` does the same for every array of a (named) tuple, nested tuples included.

The caller must keep the owner alive while the views are in use: a compiled function may take borrowed
views of its own arguments (its caller holds them for the call), not of arrays it allocates itself (numba
frees a local the moment its last named use is past).

Called from Python (the pure-Python path of a compiled function, e.g. a ``numba.cfunc`` such as the
flight loads called by the linearisation), each returns the plain array, tuple or matrix view: the same
numbers, with Python's own reference counting.
"""

from __future__ import annotations

from numba.core import cgutils, types
from numba.extending import intrinsic, overload
from numba.np.arrayobj import make_array

__all__ = ["unowned", "unowned_all", "unowned_matrix"]


def _borrowed(context, builder, ty, value):
    """The value ``value`` of type ``ty`` with every array in it made unowned (tuples member by member)."""
    if isinstance(ty, types.Array):
        src = make_array(ty)(context, builder, value=value)
        dst = make_array(ty)(context, builder)
        dst.meminfo = cgutils.get_null_value(dst.meminfo.type)
        dst.parent = cgutils.get_null_value(dst.parent.type)
        dst.nitems = src.nitems
        dst.itemsize = src.itemsize
        dst.data = src.data
        dst.shape = src.shape
        dst.strides = src.strides
        return dst._getvalue()
    if isinstance(ty, types.BaseTuple):
        out = value
        for i, member in enumerate(ty.types):
            if _holds_arrays(member):
                item = builder.extract_value(value, i)
                out = builder.insert_value(out, _borrowed(context, builder, member, item), i)
        return out
    return value


def _holds_arrays(ty) -> bool:
    return isinstance(ty, types.Array) or (isinstance(ty, types.BaseTuple) and any(_holds_arrays(t) for t in ty.types))


def unowned(a):
    """A view of the array ``a`` that holds no reference to its memory (a null meminfo; see the module
    docstring). The caller must keep ``a``'s owner alive while the view is in use. In Python: ``a``."""
    return a


def unowned_all(tup):
    """The (named) tuple ``tup`` with every array in it, at any depth, an :func:`unowned` view; its other
    members as they are. The caller must keep ``tup``'s arrays alive while the views are in use. In
    Python: ``tup``."""
    return tup


def unowned_matrix(a, start, rows, cols):
    """The ``rows`` x ``cols`` row-major matrix over ``a[start:start + rows * cols]`` of the contiguous vector
    ``a``, as a borrowed view (no bounds check: the caller keeps the stretch inside ``a`` and ``a`` alive).
    In Python: the reshaped slice, a view."""
    return a[start:start + rows * cols].reshape(rows, cols)


@intrinsic
def _unowned(typingctx, a):
    if not isinstance(a, types.Array):
        return None

    def codegen(context, builder, sig, args):
        return _borrowed(context, builder, a, args[0])

    return a(a), codegen


@intrinsic
def _unowned_all(typingctx, tup):
    if not isinstance(tup, types.BaseTuple):
        return None

    def codegen(context, builder, sig, args):
        return _borrowed(context, builder, tup, args[0])

    return tup(tup), codegen


@intrinsic
def _unowned_matrix(typingctx, a, start, rows, cols):
    if not (isinstance(a, types.Array) and a.ndim == 1 and a.layout == "C"
            and all(isinstance(v, types.Integer) for v in (start, rows, cols))):
        return None
    matrix = types.Array(a.dtype, 2, "C")

    def codegen(context, builder, sig, args):
        src = make_array(a)(context, builder, value=args[0])
        dst = make_array(matrix)(context, builder)
        intp = context.get_value_type(types.intp)
        o, r, c = (context.cast(builder, v, t, types.intp) for v, t in zip(args[1:], sig.args[1:]))
        item = context.get_constant(types.intp, context.get_abi_sizeof(context.get_data_type(a.dtype)))
        context.populate_array(dst, data=builder.gep(src.data, [o]),
                               shape=cgutils.pack_array(builder, [r, c], ty=intp),
                               strides=cgutils.pack_array(builder, [builder.mul(c, item), item], ty=intp),
                               itemsize=item, meminfo=None)
        return dst._getvalue()

    return matrix(a, start, rows, cols), codegen


@overload(unowned)
def _unowned_compiled(a):
    if isinstance(a, types.Array):
        return lambda a: _unowned(a)
    return None


@overload(unowned_all)
def _unowned_all_compiled(tup):
    if isinstance(tup, types.BaseTuple):
        return lambda tup: _unowned_all(tup)
    return None


@overload(unowned_matrix)
def _unowned_matrix_compiled(a, start, rows, cols):
    if isinstance(a, types.Array) and a.ndim == 1 and a.layout == "C":
        return lambda a, start, rows, cols: _unowned_matrix(a, start, rows, cols)
    return None

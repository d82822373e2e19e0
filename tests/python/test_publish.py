"""Context.publish borrows NumPy arrays in place, whatever their strides, and the image is the
one of the same data published C-contiguous."""
import ctypes
import gc
import weakref

import numpy as np
import pytest

import lantern
from conftest import lattice, scene_config


def address(a):
    return a.__array_interface__["data"][0]


def test_contiguous_positions_are_borrowed_not_copied(tmp_path):
    x, t = lattice()
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=x, type=t)
        assert ctx.published_pointers() == {"position": address(x), "type": address(t)}


def test_fortran_ordered_positions_become_component_views(render, tmp_path):
    x, t = lattice()
    xf = np.asfortranarray(x)
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=xf, type=t)
        pointers = ctx.published_pointers()
    n = len(x)
    assert pointers == {"position_x": address(xf), "position_y": address(xf) + 8 * n,
                        "position_z": address(xf) + 16 * n, "type": address(t)}
    assert render(position=xf, type=t) == render(position=x, type=t)


def test_strided_views_render_like_contiguous_arrays(render):
    x, t = lattice()
    n = len(x)
    wide = np.zeros((2 * n, 5))  # every other row, columns 1..3: row and column offsets
    wide[::2, 1:4] = x
    rows = wide[::2, 1:4]
    types = np.zeros(3 * n, dtype=np.int64)
    types[::3] = t
    reference = render(position=x, type=t)
    assert render(position=rows, type=types[::3]) == reference
    assert render(position_x=x[:, 0], position_y=x[:, 1], position_z=x[:, 2],
                  type=t) == reference
    assert render(position=x.astype(np.float32), type=t) == reference


def test_structured_array_fields_are_borrowed_in_place(render, tmp_path):
    x, t = lattice()
    atoms = np.zeros(len(x), dtype=[("id", "i8"), ("x", "f8", 3), ("type", "i4")])
    atoms["x"], atoms["type"] = x, t
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=atoms["x"], type=atoms["type"])
        assert ctx.published_pointers()["position"] == address(atoms) + 8
        assert ctx.published_pointers()["type"] == address(atoms) + 32
    assert render(position=atoms["x"], type=atoms["type"]) == render(position=x, type=t)


def test_ctypes_and_array_interface_objects_are_borrowed(render, tmp_path):
    x, t = lattice()
    c_positions = (ctypes.c_double * 3 * len(x))()
    np.frombuffer(c_positions, dtype=np.float64).reshape(-1, 3)[:] = x

    class Interface:  # only __array_interface__, no buffer protocol
        def __init__(self, a):
            self.__array_interface__ = a.__array_interface__

    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=c_positions, type=Interface(t))
        assert ctx.published_pointers() == {"position": ctypes.addressof(c_positions),
                                            "type": address(t)}
    assert render(position=c_positions, type=Interface(t)) == render(position=x, type=t)


def test_an_array_interface_with_fewer_strides_than_axes_is_refused(tmp_path):
    """The publish read one stride per axis: a hand-made interface with fewer read past them."""
    x, _ = lattice()

    class Interface:
        def __init__(self, a):
            self.__array_interface__ = dict(a.__array_interface__, strides=(24,))

    with lantern.Context(scene_config(tmp_path)) as ctx:
        with pytest.raises(ValueError, match="1 strides for 2 axes"):
            ctx.publish(position=Interface(x))


def test_lantern_reads_the_array_at_execute_time(tmp_path):
    """Modifying the published array in place changes the next image: Lantern reads it."""
    x, t = lattice()
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=x, type=t)
        ctx.execute(0, 0.0)
        x[: len(x) // 2, 2] += 10.0  # half the particles move up, in place
        ctx.execute(1, 0.1)
    moved = x.copy()
    with lantern.Context(scene_config(tmp_path / "copy")) as ctx:
        ctx.publish(position=moved, type=t)
        ctx.execute(1, 0.1)
    before = (tmp_path / "frame_000000.png").read_bytes()
    after = (tmp_path / "frame_000001.png").read_bytes()
    assert after != before
    assert after == (tmp_path / "copy" / "frame_000001.png").read_bytes()


def test_published_arrays_are_held_until_the_next_publish_or_close(tmp_path):
    x, t = lattice()
    held = weakref.ref(x)
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=x)
        del x
        gc.collect()
        assert held() is not None  # the context holds the array Lantern borrows
        ctx.publish(position=lattice()[0])
        gc.collect()
        assert held() is None  # released by the next publish
        again = lattice()[0]
        held = weakref.ref(again)
        ctx.publish(position=again)
        del again
    gc.collect()
    assert held() is None  # and by close


def test_the_context_keeps_published_arrays_alive(render, tmp_path):
    x, t = lattice()
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=x.copy(), type=t.copy())  # the only references are the context's
        gc.collect()
        ctx.execute(0, 0.0)
    assert (tmp_path / "frame_000000.png").read_bytes() == render(position=x, type=t)


def test_mask_is_passed_through(tmp_path):
    """Only that the pointer and bits reach lantern_publish; drawing by mask is core's (branch
    lammps)."""
    x, t = lattice()
    mask = np.ones(len(x), dtype=np.int64)
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=x, mask=mask, mask_bits=1)
        assert ctx.published_pointers()["mask"] == address(mask)


def refusal(match, **arrays):
    with lantern.Context(scene_config("unused")) as ctx:
        with pytest.raises(ValueError, match=match):
            ctx.publish(**arrays)


class Interface:
    """An object with only an __array_interface__, its data a real buffer of 1 kB."""
    _memory = np.zeros(1024, dtype=np.uint8)

    def __init__(self, typestr, shape, strides=None):
        self.__array_interface__ = {"typestr": typestr, "shape": shape, "strides": strides,
                                    "data": (Interface._memory.ctypes.data, False), "version": 3}


@pytest.mark.parametrize("arrays, match", [
    (dict(position=lattice(2)[0].astype(">f8")), r"^position: dtype >f8 has non-native byte"),
    (dict(position=lattice(2)[0].astype(np.float16)), r"^position: dtype float16 is not supported"),
    (dict(position=lattice(2)[0], type=np.zeros(8, np.uint32)), r"^type: dtype uint32 is not"),
    (dict(position=lattice(2)[0], radius=np.zeros(8, np.int32)), r"^radius: dtype int32 is not"),
    (dict(position=lattice(2)[0].tolist()), r"^position: cannot borrow a list"),
    (dict(position=np.zeros((8, 2))), r"^position: shape \(8, 2\) is not \(n, 3\)"),
    (dict(position=np.zeros(24)), r"^position: shape \(24,\) is not \(n, 3\)"),
    (dict(position=lattice(2)[0], scalar=np.zeros((8, 1))), r"^scalar: shape \(8, 1\) is not one"),
    (dict(position=lattice(2)[0], radius=np.ones(7)), r"^radius: 7 elements, but there are 8"),
    (dict(position=lattice(2)[0][::-1]), r"^position: row stride is negative"),
    (dict(position=np.broadcast_to(np.zeros(3), (8, 3))), r"^position: row stride is 0"),
    (dict(position=lattice(2)[0], radius=np.lib.stride_tricks.as_strided(
        np.zeros(16), shape=(8,), strides=(4,))), r"^radius: element stride of 4 bytes is not a whole"),
    (dict(position=lattice(2)[0], position_x=np.zeros(8)), r"^position: give either"),
    (dict(position_x=np.zeros(8)), r"^position_x/y/z: give all three"),
    (dict(type=np.zeros(8, np.int32)), r"^type: 8 elements, but there are 0"),
    # A 0-d array (a NumPy scalar) has no axes: it was reported as shape (1,).
    (dict(position=np.array(1.0)), r"^position: shape \(\) \(a 0-d array: one number"),
    (dict(position=lattice(2)[0], radius=np.float64(0.5)), r"^radius: shape \(\) \(a 0-d array"),
    # Made-up __array_interface__s (found by fuzz_python_publish): an item size too large for
    # int64 raised IndexError ("stoll"), a shape of non-integers pybind11's RuntimeError.
    (dict(position=Interface("<f99999999999999999999", (8, 3))), r"^position: __array_interface__ typestr '<f9+' is malformed"),
    (dict(position=Interface("<f8", ("8", 3))), r"^position: __array_interface__ is malformed"),
    (dict(position=Interface("<f8", (8, 3), strides=(2**70, 8))), r"^position: __array_interface__ is malformed"),
])
def test_what_cannot_be_borrowed_is_refused_naming_the_array(arrays, match):
    refusal(match, **arrays)


def test_a_refused_publish_leaves_the_previous_one_in_place(tmp_path):
    x, t = lattice()
    with lantern.Context(scene_config(tmp_path)) as ctx:
        ctx.publish(position=x, type=t)
        with pytest.raises(ValueError):
            ctx.publish(position=x, type=t[:-1])
        assert ctx.published_pointers()["position"] == address(x)

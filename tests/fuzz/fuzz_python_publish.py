"""The Python side of fuzz_python_publish: turns the fuzzer's bytes into arguments of
lantern.Context.publish - NumPy arrays of any dtype, shape, strides and offset over a buffer,
memoryviews, objects with a made-up __array_interface__ (whose data always lies inside a real
buffer, so any out-of-bounds read would be Lantern's), 0-d arrays, scalars and other objects -
and calls publish, then execute on a tiny scene when publish accepted them.

The expected outcomes are ValueError, TypeError, OverflowError (an argument Lantern or pybind11
refuses) and lantern.Error (one the C API refuses). run() returns False for anything else, which
the C++ harness turns into a crash for libFuzzer to keep."""
import numpy as np

import lantern

DTYPES = ["<f4", "<f8", "<i4", "<i8", ">f8", ">i4", "<u4", "<f2", "<c8", "|b1", "<i2", "|u1"]
TYPESTRS = ["<f8", "<f4", "<i4", "<i8", ">f8", "<u8", "<f16", "|V8", "<f", "", "x", "<f99999999999999999999", "<i0"]
FIELDS = ["position", "position_x", "position_y", "position_z", "radius", "scalar", "type", "id",
          "mask"]
ARENA = np.zeros(8192, dtype=np.uint8)  # every array's memory (the middle is the base address)
EXPECTED = (ValueError, TypeError, OverflowError, lantern.Error)


class Reader:
    def __init__(self, data):
        self.data, self.at = data, 0

    def byte(self):
        if self.at >= len(self.data):
            return 0
        self.at += 1
        return self.data[self.at - 1]

    def signed(self, scale=1):
        return (self.byte() - 128) * scale


class Interface:
    """An object that only has __array_interface__."""

    def __init__(self, interface):
        self.__array_interface__ = interface


def from_interface(r):
    typestr = TYPESTRS[r.byte() % len(TYPESTRS)]
    ndim = r.byte() % 4
    shape = tuple(r.byte() % 9 for _ in range(ndim))
    strides = None if r.byte() % 3 == 0 else tuple(r.signed(r.byte() % 17) for _ in range(ndim))
    itemsize = 8
    lo = hi = 0
    for extent, stride in zip(shape, strides or [itemsize] * ndim):
        if extent == 0:
            lo = hi = 0
            break
        step = (extent - 1) * stride
        lo, hi = lo + min(step, 0), hi + max(step, 0)
    if lo < -4000 or hi > 4000:  # keep every byte it may address inside ARENA
        return None
    base = ARENA.__array_interface__["data"][0] + 4096
    interface = {"typestr": typestr, "shape": shape, "data": (base, False), "version": 3}
    if r.byte() % 4:
        interface["strides"] = strides
    if r.byte() % 11 == 0:
        del interface["data"]
    return Interface(interface)


def make_argument(r):
    kind = r.byte() % 7
    if kind == 0:
        return None
    if kind in (1, 2):
        dtype = np.dtype(DTYPES[r.byte() % len(DTYPES)])
        ndim = r.byte() % 4
        shape = tuple(r.byte() % 9 for _ in range(ndim))
        strides = None if r.byte() % 2 else tuple(r.signed(r.byte() % 9) for _ in range(ndim))
        offset = r.byte() % 64
        try:
            a = np.ndarray(shape, dtype, buffer=ARENA, offset=4096 + offset, strides=strides)
        except (ValueError, TypeError):
            return None
        return memoryview(a) if kind == 2 and r.byte() % 2 else a
    if kind == 3:
        return from_interface(r)
    if kind == 4:
        return np.float64(r.signed()) if r.byte() % 2 else np.array(r.signed(), dtype=np.float64)
    if kind == 5:
        return [r.signed() for _ in range(r.byte() % 4)]
    return ["text", b"bytes", 3, 2.5, object()][r.byte() % 5]


def run(context, data):
    r = Reader(data)
    kwargs = {}
    for field in FIELDS:
        if r.byte() % 3 == 0:
            argument = make_argument(r)
            if argument is not None:
                kwargs[field] = argument
    if r.byte() % 5 == 0:
        kwargs["mask_bits"] = r.signed(1 << (r.byte() % 64))
    try:
        context.publish(**kwargs)
    except EXPECTED:
        return True
    except Exception as e:  # noqa: BLE001 - any other exception is a finding
        print("unexpected from publish:", type(e).__name__, e)
        return False
    try:
        context.execute(0, 0.0)
    except EXPECTED:
        return True
    except Exception as e:  # noqa: BLE001
        print("unexpected from execute:", type(e).__name__, e)
        return False
    return True

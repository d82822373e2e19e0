"""lantern.Context's life cycle and lantern.Error."""
import pathlib

import numpy as np
import pytest

import lantern
from conftest import lattice, scene_config


def test_a_bad_configuration_raises_lantern_error_with_status():
    with pytest.raises(lantern.Error) as caught:
        lantern.Context("scenes:\n  - widht: 10\n")
    e = caught.value
    assert isinstance(e, RuntimeError)
    assert e.status == lantern.ERR_CONFIG == 3
    assert e.status_name == "LANTERN_ERR_CONFIG"
    assert "widht" in e.message and "width" in e.message
    assert str(e).startswith("LANTERN_ERR_CONFIG: ")


def test_errors_of_the_c_api_carry_its_status_and_message(tmp_path):
    with lantern.Context(scene_config(tmp_path)) as ctx:
        with pytest.raises(lantern.Error) as caught:
            ctx.set_box([0, 0, 0], [1, -1, 1])
        assert caught.value.status == lantern.ERR_INVALID_ARGUMENT
        assert "high" in caught.value.message or "low" in caught.value.message
        ctx.set_box([0, 0, 0], [4, 4, 4], periodic=[True, True, False])  # still usable


def test_a_config_path_is_accepted(tmp_path):
    path = tmp_path / "run.yaml"
    path.write_text(scene_config(tmp_path))
    x, t = lattice()
    for config in (path, str(path)):
        with lantern.Context(config) as ctx:
            ctx.publish(x, type=t)
            ctx.execute(3, 0.0)
    assert (tmp_path / "frame_000003.png").stat().st_size > 0


def test_the_context_manager_closes_even_after_an_exception(tmp_path):
    x, t = lattice()
    with pytest.raises(KeyError):
        with lantern.Context(scene_config(tmp_path)) as ctx:
            ctx.publish(position=x, type=t)
            ctx.execute(0, 0.0)
            raise KeyError("simulation failed")
    assert ctx.closed
    assert ctx.published_pointers() == {}  # nothing borrowed any more
    with pytest.raises(lantern.Error) as caught:
        ctx.execute(1, 0.0)
    assert caught.value.status == lantern.ERR_INVALID_ARGUMENT
    assert "closed" in caught.value.message
    ctx.close()  # a second close does nothing


def test_a_mpi4py_communicator_is_accepted(tmp_path):
    from mpi4py import MPI
    x, t = lattice()
    with lantern.Context(scene_config(tmp_path), comm=MPI.COMM_WORLD) as ctx:
        ctx.publish(position=x, type=t)
        ctx.execute(0, 0.0)
    with pytest.raises(TypeError, match="comm: expected an mpi4py communicator"):
        lantern.Context(scene_config(tmp_path), comm="world")


def test_version_and_status_constants():
    assert lantern.__version__.count(".") == 2
    assert (lantern.OK, lantern.ERR_IO, lantern.ERR_INTERNAL) == (0, 4, 8)

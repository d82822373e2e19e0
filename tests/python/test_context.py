"""lantern.Context's life cycle and lantern.Error."""
import pathlib
import resource
import signal
import subprocess
import sys
import textwrap
import warnings

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
        with pytest.raises(lantern.Error) as caught:
            ctx.set_box([0, 0, 0], [4, 4, 4], tilt=[1.0, float("nan"), 0.0])
        assert "tilt[1] (xz) is not finite" in caught.value.message
        ctx.set_box([0, 0, 0], [4, 4, 4], periodic=[True, True, True], tilt=[1.0, -0.5, 0.25])


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


def test_a_nul_in_the_configuration_or_its_path_is_refused(tmp_path):
    # Everything after the NUL was silently ignored: here the misspelt key.
    with pytest.raises(ValueError, match=r"^config: a NUL character at offset 19"):
        lantern.Context(scene_config(tmp_path)[:19] + "\0" + scene_config(tmp_path)[19:])
    with pytest.raises(ValueError, match="NUL"):
        lantern.Context(scene_config(tmp_path) + "\0widht: 1\n")
    path = tmp_path / "run.yaml"
    path.write_text(scene_config(tmp_path))
    with pytest.raises(ValueError, match="NUL"):
        lantern.Context(str(path) + "\0.bak")


def test_an_exception_in_the_with_block_stays_primary_when_close_fails(tmp_path):
    """The block's exception is what the caller sees; the close error (an image written in the
    background that hit a full disk) is a RuntimeWarning next to it."""
    x, t = lattice()
    config = scene_config(tmp_path).replace(".png'}", ".png', asynchronous: true}")
    saved = resource.getrlimit(resource.RLIMIT_FSIZE)
    previous = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    try:
        with pytest.warns(RuntimeWarning, match="closing the context while an exception"):
            with pytest.raises(KeyError, match="simulation failed"):
                with lantern.Context(config) as ctx:
                    ctx.publish(position=x, type=t)
                    resource.setrlimit(resource.RLIMIT_FSIZE, (100, saved[1]))  # a full disk
                    ctx.execute(0, 0.0)  # the image is written in the background, and fails
                    raise KeyError("simulation failed")
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, saved)
        signal.signal(signal.SIGXFSZ, previous)
    assert ctx.closed
    # Without an exception in the block, the close error is raised as before.
    with pytest.raises(lantern.Error, match="could not be read or written"):
        try:
            with lantern.Context(config) as ctx:
                ctx.publish(position=x, type=t)
                resource.setrlimit(resource.RLIMIT_FSIZE, (100, saved[1]))
                ctx.execute(0, 0.0)
        finally:
            resource.setrlimit(resource.RLIMIT_FSIZE, saved)


def test_a_communicator_handle_that_is_not_one_is_an_error_not_an_abort(tmp_path):
    with pytest.raises(lantern.Error) as caught:
        lantern.Context(scene_config(tmp_path), comm=100)
    assert caught.value.status == lantern.ERR_MPI
    assert "mpi_comm_f: 100 is not a valid communicator handle" in caught.value.message


def test_mpi_finalized_before_close_is_an_error_not_an_abort(tmp_path):
    """mpi4py's MPI.Finalize() with a context still open: close raises lantern.Error (MPI), the
    interpreter exits normally. In a child interpreter: MPI cannot start again in this one."""
    script = textwrap.dedent(f"""
        import numpy as np, lantern
        from mpi4py import MPI
        ctx = lantern.Context({scene_config(tmp_path)!r})
        ctx.publish(position=np.zeros((4, 3)))
        ctx.execute(0, 0.0)
        MPI.Finalize()
        try:
            ctx.close()
        except lantern.Error as e:
            print("closed:", e.status_name, e.message)
        """)
    pytest.importorskip("mpi4py")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "closed: LANTERN_ERR_MPI" in done.stdout, done.stdout + done.stderr
    assert "communicator is invalid" in done.stdout  # LANTERN_ERR_MPI's description
    assert "MPI was finalized (MPI_Finalize)" in done.stderr  # lantern_close's details

"""Renders trajectories of any format MDAnalysis reads (XTC, TRR, DCD, GRO, PDB, LAMMPS dumps,
H5MD, ...) through Lantern's pipeline, offline, under MPI.

    mpiexec -n 4 python3 -m lantern.render TOPOLOGY TRAJECTORY -lantern viz.yaml \\
        [--every N] [--frames a:b] [--types auto|element|name|type|resname|none] \\
        [--scalar speed|force|ATTRIBUTE] [--split atoms|frames] [--option KEY=VALUE ...]

or, from Python, ``render_universe(universe, config, ...)`` with an MDAnalysis Universe (or an
AtomGroup: a selection, such as ``u.select_atoms("protein")``).

Every selected frame is published and rendered at its step (the trajectory's own step numbers
where the format has them, else the frame index), so the configuration's ``schedule:`` still
applies; use one without a schedule to render every selected frame. Lengths are MDAnalysis's:
Angstrom. A Universe's positions are borrowed from MDAnalysis's frame buffer (float32), never
copied; an AtomGroup's are gathered by MDAnalysis into a new array each frame.

MPI: with ``split='atoms'`` (the default) every rank reads every frame and publishes its share of
the atoms (a contiguous range), and all ranks render each frame together; with
``split='frames'`` each rank renders whole frames of its own (frame k on rank k mod size, each
rank with its own Lantern context), which scales better for many small frames but cannot write
one stats file or one particle dump (those configurations are refused). Images are the same
either way and at any rank count.
"""
import argparse
import ast
import os
import sys
import warnings

import numpy as np

from . import Context, Error

_TYPES = ("auto", "element", "name", "type", "resname", "none")
_ATTRIBUTES = {"element": "elements", "name": "names", "type": "types", "resname": "resnames"}


def _world():
    """mpi4py's COMM_WORLD, or None when mpi4py is not installed (one process)."""
    try:
        from mpi4py import MPI
    except ImportError:
        return None
    return MPI.COMM_WORLD


def _labels(atoms, kind):
    """The topology's labels of one kind ('element', 'name', 'type', 'resname') as strings, or
    None when it has none (or only empty ones)."""
    from MDAnalysis.exceptions import NoDataError
    try:
        labels = np.asarray(getattr(atoms, _ATTRIBUTES[kind])).astype(str)
    except (NoDataError, AttributeError):
        return None
    return labels if len(labels) and any(labels) else None


def _is_integer(labels):
    return all(s.lstrip("-").isdigit() for s in labels)


def atom_types(atoms, types="auto"):
    """Integer types of an AtomGroup, and the label of each type (list, index = type).

    Integer labels stay what they are (LAMMPS's numeric types); other labels become their index
    among the sorted distinct labels, whatever the atoms' order. 'auto': integer `types`, else
    elements, else atom names, else (guessed) types, else none. 'none': (None, [])."""
    if types == "none":
        return None, []
    if types == "auto":
        found = _labels(atoms, "type")
        if found is None or not _is_integer(found):
            found = next((labels for labels in (_labels(atoms, "element"),
                                                 _labels(atoms, "name"), found)
                          if labels is not None), None)
        if found is None:
            return None, []
    else:
        found = _labels(atoms, types)
        if found is None:
            raise ValueError(f"types={types!r}: the topology has no {_ATTRIBUTES[types]}")
    if _is_integer(found):
        values = found.astype(np.int64)
        return values.astype(np.int32), [str(v) for v in range(max(values.max() + 1, 0))]
    names, index = np.unique(found, return_inverse=True)
    return index.astype(np.int32), [str(n) for n in names]


def _scalar_reader(atoms, scalar, whole=True):
    """A function of the current frame returning the per-atom scalar (float64), or None. whole:
    the atoms are all of the frame's, in order (else their vectors are gathered from it)."""
    if scalar is None:
        return None
    if scalar in ("speed", "force"):
        def magnitude(ts):
            if scalar == "speed" and not ts.has_velocities:
                raise ValueError(f"scalar 'speed': frame {ts.frame} has no velocities")
            if scalar == "force" and not ts.has_forces:
                raise ValueError(f"scalar 'force': frame {ts.frame} has no forces")
            source = ts if whole else atoms
            vectors = source.velocities if scalar == "speed" else source.forces
            return np.sqrt(np.einsum("ij,ij->i", vectors, vectors, dtype=np.float64))
        return magnitude
    try:
        values = np.asarray(getattr(atoms, scalar), dtype=np.float64)
    except Exception as e:  # NoDataError, AttributeError, a non-numeric attribute
        raise ValueError(f"scalar {scalar!r}: not a per-atom attribute of the topology "
                         f"({e})") from None
    if values.shape != (len(atoms),):
        raise ValueError(f"scalar {scalar!r}: shape {values.shape}, expected ({len(atoms)},)")
    return lambda ts: values


def _atom_ids(atoms):
    """The topology's atom ids, or 1..n where it has none."""
    from MDAnalysis.exceptions import NoDataError
    try:
        return np.asarray(atoms.ids)
    except NoDataError:
        return np.arange(1, len(atoms) + 1)


def parse_frames(text):
    """'a:b', 'a:', ':b' or 'a:b:c' (Python slice of frame indices, end excluded) -> slice."""
    parts = text.split(":")
    if len(parts) not in (2, 3):
        raise ValueError(f"--frames {text!r}: expected a:b (frame indices, end excluded)")
    try:
        values = [int(p) if p.strip() else None for p in parts]
    except ValueError:
        raise ValueError(f"--frames {text!r}: a and b must be integers") from None
    return slice(*values)


def _config_has(config, keys):
    """The top-level keys among `keys` that the YAML configuration (text or path) sets."""
    import yaml
    text = config
    if "\n" not in config and not config.lstrip().startswith("{") and os.path.exists(config):
        with open(config) as f:
            text = f.read()
    document = yaml.safe_load(text) or {}
    return [k for k in keys if isinstance(document, dict) and k in document]


def render_universe(universe, config, *, every=1, frames=None, types="auto", scalar=None,
                    split="atoms", comm=None, progress=True):
    """Renders the frames of an MDAnalysis Universe (or of an AtomGroup's atoms) through Lantern;
    returns how many frames this rank rendered.

    config: Lantern's configuration (YAML text or a path). every: render every N-th selected
    frame. frames: a slice of frame indices (or 'a:b'), None for all. types, scalar: as the
    command's --types and --scalar. split: 'atoms' or 'frames' (see the module's doc). comm: an
    mpi4py communicator (None: COMM_WORLD when mpi4py is there, else one process). progress: a
    progress bar on rank 0's stderr."""
    from MDAnalysis.lib.log import ProgressBar
    if int(every) < 1:
        raise ValueError(f"every must be a positive integer, not {every!r}")
    if isinstance(frames, str):
        frames = parse_frames(frames)
    if split not in ("atoms", "frames"):
        raise ValueError(f"split must be 'atoms' or 'frames', not {split!r}")
    if types not in _TYPES:
        raise ValueError(f"types must be one of {_TYPES}, not {types!r}")
    comm = comm if comm is not None else _world()
    rank, size = (comm.rank, comm.size) if comm is not None else (0, 1)
    atoms = universe.atoms  # a Universe's, or the AtomGroup itself
    whole = atoms is atoms.universe.atoms or hasattr(universe, "trajectory")
    universe = atoms.universe
    type_array, _ = atom_types(atoms, types)
    scalar_of = _scalar_reader(atoms, scalar, whole)
    selected = range(len(universe.trajectory))[frames if frames is not None else slice(None)]
    selected = selected[::int(every)]

    if split == "frames" and (clashing := _config_has(config, ("stats", "dump"))):
        # Refused at any rank count, so that a configuration does not fail only when scaled up.
        raise ValueError(f"--split frames: each rank renders its own frames, so one "
                         f"{' and one '.join(clashing)} file cannot be written; use "
                         f"--split atoms")
    if split == "frames" and size > 1:
        from mpi4py import MPI
        context = Context(config, MPI.COMM_SELF)
        mine, share = selected[rank::size], slice(None)
    else:
        context = Context(config, comm)
        mine = selected
        share = slice(rank * len(atoms) // size, (rank + 1) * len(atoms) // size)

    ids = np.ascontiguousarray(_atom_ids(atoms)[share], dtype=np.int64)
    types_mine = type_array[share] if type_array is not None else None
    # Ranks that render frames together agree on every frame's local errors before rendering it,
    # so that no rank waits in a collective for one that failed.
    together = comm if split == "atoms" and size > 1 else None
    rendered = 0
    with context:
        bar = ProgressBar(mine, disable=not progress or rank != 0, desc="lantern.render",
                          unit="frame", file=sys.stderr)
        for index in bar:
            error, ts = None, None
            try:
                ts = universe.trajectory[index]
                positions = ts.positions if whole else atoms.positions
                arrays = {"position": positions[share], "id": ids}
                if types_mine is not None:
                    arrays["type"] = types_mine
                if scalar_of is not None:
                    arrays["scalar"] = np.ascontiguousarray(scalar_of(ts)[share])
                context.publish(**arrays)
                dims = ts.dimensions
                if dims is not None and np.all(dims[:3] > 0):
                    set_box(context, dims)
            except (Error, ValueError, OSError, EOFError) as e:
                error = f"frame {index}: {e}"
            if error := agree(together, error):
                raise ValueError(error)
            step = int(ts.data.get("step", ts.frame))
            context.execute(step, float(ts.time))  # collective: the same outcome on every rank
            rendered += 1
    return rendered


def set_box(context, dims):
    """The box of MDAnalysis's dimensions (a, b, c, alpha, beta, gamma): orthogonal where the
    angles are 90 degrees, else triclinic from MDAnalysis's own reduced vectors (a along x, b in
    the xy plane: LAMMPS's restricted form)."""
    if np.allclose(dims[3:], 90.0):
        context.set_box((0.0, 0.0, 0.0), tuple(float(d) for d in dims[:3]), (True, True, True))
        return
    from MDAnalysis.lib.mdamath import triclinic_vectors
    a, b, c = (np.asarray(v, dtype=float) for v in triclinic_vectors(dims))
    context.set_box((0.0, 0.0, 0.0), (a[0], b[1], c[2]), (True, True, True),
                    tilt=(b[0], c[0], c[1]))


def agree(comm, error):
    """The first rank's error (or None) on every rank of comm (None: this process alone)."""
    if comm is None:
        return error
    return next((e for e in comm.allgather(error) if e), None)


def _frames_option(text):
    try:
        return parse_frames(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _option(text):
    """KEY=VALUE for mda.Universe: VALUE as a Python literal when it is one, else a string."""
    key, sep, value = text.partition("=")
    if not sep or not key.isidentifier():
        raise argparse.ArgumentTypeError(f"--option {text!r}: expected KEY=VALUE")
    try:
        return key, ast.literal_eval(value)
    except (ValueError, SyntaxError):
        return key, value


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python3 -m lantern.render",
        description="Renders a trajectory that MDAnalysis reads through Lantern's pipeline.")
    parser.add_argument("topology", help="topology (or a file MDAnalysis infers one from)")
    parser.add_argument("trajectory", nargs="*", help="trajectory files (none: the topology's "
                        "own coordinates)")
    parser.add_argument("-lantern", "--lantern", dest="config", required=True,
                        help="Lantern's configuration (YAML file)")
    parser.add_argument("--every", type=int, default=1, help="render every N-th frame")
    parser.add_argument("--frames", type=_frames_option, default=None,
                        help="a:b, frame indices to render (b excluded)")
    parser.add_argument("--types", choices=_TYPES, default="auto")
    parser.add_argument("--scalar", default=None,
                        help="speed, force, or a per-atom attribute (charges, masses, ...)")
    parser.add_argument("--split", choices=("atoms", "frames"), default="atoms")
    parser.add_argument("--option", type=_option, action="append", default=[],
                        help="KEY=VALUE passed to MDAnalysis.Universe (e.g. format=LAMMPSDUMP, "
                        "atom_style='id type x y z', convert_units=False)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    if args.every < 1:
        parser.error("--every must be a positive integer")
    comm = _world()
    rank = comm.rank if comm is not None else 0
    try:
        with warnings.catch_warnings():
            # MDAnalysis 2.4 imports xdrlib (deprecated in Python 3.11) after installing a
            # filter of its own: import it first, quietly. Its guesses (masses, dt) are not ours
            # to report either.
            warnings.simplefilter("ignore", DeprecationWarning)
            try:
                import xdrlib  # noqa: F401
            except ImportError:
                pass
        import MDAnalysis
        warnings.filterwarnings("ignore", category=UserWarning, module="MDAnalysis")
        warnings.filterwarnings("ignore", message="Reader has no dt information")
        universe, error = None, None
        try:
            universe = MDAnalysis.Universe(args.topology, *args.trajectory, **dict(args.option))
        except Exception as e:  # MDAnalysis raises many kinds for files it cannot read
            error = f"{args.topology} {' '.join(args.trajectory)}: {type(e).__name__}: {e}"
        if error := agree(comm if comm is not None and comm.size > 1 else None, error):
            raise ValueError(error)
        count = render_universe(universe, args.config, every=args.every, frames=args.frames,
                                types=args.types, scalar=args.scalar, split=args.split,
                                comm=comm, progress=not args.quiet)
    except (Error, ValueError, OSError) as e:  # the same on every rank (agreed, or collective)
        if rank == 0:
            print(f"lantern.render: error: {e}", file=sys.stderr)
        return 1
    total = comm.allreduce(count) if comm is not None else count
    if rank == 0 and not args.quiet:
        print(f"lantern.render: {total} frames rendered", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

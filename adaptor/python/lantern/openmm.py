"""Renders an OpenMM simulation in situ: a reporter for ``simulation.reporters``.

    from lantern.openmm import Reporter
    simulation.reporters.append(Reporter("viz.yaml", 1000, types="element", scalar="speed"))

Every ``report_interval`` steps OpenMM hands the reporter a ``State`` and the reporter renders
it through Lantern (``Context.execute`` at ``simulation.currentStep``, time in ps); Lantern's
``schedule:`` may thin the reports further.

What is copied: OpenMM keeps positions on its device (GPU or CPU platform) and hands them over
only as a copy, made by ``Context.getState`` into the ``State``; Python cannot borrow OpenMM's own
arrays. The reporter copies the ``State``'s positions exactly once per report, into one float64
``(n, 3)`` buffer (nm) allocated at the first report and published to Lantern once; later reports
overwrite it in place, so nothing is re-published or re-allocated. Per-atom scalars other than a
callable's get the same treatment (velocities or forces copied once into their own reused
buffer, the magnitude written in place into the published scalar buffer).

Units are OpenMM's: lengths in nm (so the configuration's radius and camera too), time in ps.
"""
import numpy as np
import openmm
from openmm import unit

from . import Context

_SCALARS = ("speed", "force", "kinetic_energy")
_TYPES = ("element", "residue", "name")


def type_labels(topology, types):
    """The label of each atom of an OpenMM Topology: its element's symbol ('' for none), its
    residue's name or its own name."""
    if types == "element":
        return [atom.element.symbol if atom.element is not None else "" for atom in
                topology.atoms()]
    if types == "residue":
        return [atom.residue.name for atom in topology.atoms()]
    return [atom.name for atom in topology.atoms()]


def label_indices(labels):
    """Integer types for labels: each label's index among the sorted distinct labels (so the same
    labels give the same types whatever the atoms' order). Returns (int32 array, sorted names)."""
    names, indices = np.unique(np.asarray(labels, dtype=object).astype(str), return_inverse=True)
    return indices.astype(np.int32), [str(n) for n in names]


def _copy_vectors(state, which, out):
    """Copies the State's positions, velocities or forces into `out` ((n, 3) float64): once, with
    the State's own copying method (OpenMM 7.7 and later have it), else through getPositions and
    friends, which allocate a new array first."""
    if hasattr(state, "_getVectorAsNumpy"):
        state._getVectorAsNumpy(which, out)
        return
    get, length = {openmm.State.Positions: (state.getPositions, unit.nanometer),
                   openmm.State.Velocities: (state.getVelocities,
                                             unit.nanometer / unit.picosecond),
                   openmm.State.Forces: (state.getForces,
                                         unit.kilojoule_per_mole / unit.nanometer)}[which]
    out[:] = get(asNumpy=True).value_in_unit(length)


class Reporter:
    """An OpenMM reporter that renders the simulation with Lantern.

    config: Lantern's configuration (YAML text or a path), as for lantern.Context.
    report_interval: steps between reports.
    types: 'element' (default), 'residue' or 'name': atoms' integer types are the index of their
        label among the sorted distinct labels of the topology (``type_names`` lists them);
        None publishes no types.
    scalar: None, 'speed' (|v|, nm/ps), 'force' (|F|, kJ/mol/nm), 'kinetic_energy' (m v^2 / 2,
        kJ/mol), or a callable ``f(simulation, state)`` returning n values (copied each report).
    wrap: positions wrapped into the periodic box (True), not (False), or as OpenMM decides
        (None: wrapped when the system is periodic).
    comm: an mpi4py communicator (None: MPI_COMM_WORLD; OpenMM runs on one process, so usually
        one rank).

    Use close() (or a ``with`` block) to flush the outputs when done; contexts still open are
    closed at exit.
    """

    def __init__(self, config, report_interval, *, types="element", scalar=None, wrap=None,
                 comm=None):
        if int(report_interval) < 1:
            raise ValueError(f"report_interval must be a positive number of steps, "
                             f"not {report_interval!r}")
        if types is not None and types not in _TYPES:
            raise ValueError(f"types must be one of {_TYPES} or None, not {types!r}")
        if scalar is not None and not callable(scalar) and scalar not in _SCALARS:
            raise ValueError(f"scalar must be one of {_SCALARS}, a callable or None, "
                             f"not {scalar!r}")
        self._interval = int(report_interval)
        self._types = types
        self._scalar = scalar
        self._wrap = wrap
        self.context = Context(config, comm)
        self.type_names = []
        self._positions = None  # the published (n, 3) float64 buffer, nm
        self._vectors = None    # velocities or forces, copied from the State
        self._values = None     # the published scalar buffer
        self._half_masses = None

    def describeNextReport(self, simulation):
        """OpenMM's reporter protocol: steps to the next report and what it needs."""
        steps = self._interval - simulation.currentStep % self._interval
        return (steps, True, self._scalar in ("speed", "kinetic_energy"), self._scalar == "force",
                False, self._wrap)

    def report(self, simulation, state):
        """OpenMM's reporter protocol: renders the State (Lantern's schedule permitting)."""
        if self._positions is None:
            self._publish(simulation)
        _copy_vectors(state, openmm.State.Positions, self._positions)
        if self._scalar is not None:
            self._fill_scalar(simulation, state)
        if simulation.system.usesPeriodicBoundaryConditions():
            box = state.getPeriodicBoxVectors(asNumpy=True).value_in_unit(unit.nanometer)
            # OpenMM's reduced box vectors: a along x, b in the xy plane - LAMMPS's restricted
            # triclinic form: lengths a_x, b_y, c_z and tilts b_x, c_x, c_y.
            edges = tuple(float(e) for e in np.diagonal(box))
            tilt = (float(box[1][0]), float(box[2][0]), float(box[2][1]))
            if any(tilt):
                self.context.set_box((0.0, 0.0, 0.0), edges, (True, True, True), tilt=tilt)
            else:
                self.context.set_box((0.0, 0.0, 0.0), edges, (True, True, True))
        time = state.getTime().value_in_unit(unit.picosecond)
        self.context.execute(simulation.currentStep, time)

    def close(self):
        """Flushes Lantern's outputs and closes its context (collective)."""
        self.context.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _publish(self, simulation):
        """First report: allocates the buffers and publishes them, once for the whole run."""
        n = simulation.system.getNumParticles()
        self._positions = np.zeros((n, 3), dtype=np.float64)
        arrays = {"position": self._positions, "id": np.arange(n, dtype=np.int64)}
        if self._types is not None:
            arrays["type"], self.type_names = label_indices(
                type_labels(simulation.topology, self._types))
        if self._scalar is not None:
            self._values = np.zeros(n, dtype=np.float64)
            arrays["scalar"] = self._values
            if self._scalar in ("speed", "force", "kinetic_energy"):
                self._vectors = np.zeros((n, 3), dtype=np.float64)
            if self._scalar == "kinetic_energy":
                dalton = unit.dalton
                self._half_masses = 0.5 * np.array(
                    [simulation.system.getParticleMass(i).value_in_unit(dalton) for i in range(n)])
        self.context.publish(**arrays)

    def _fill_scalar(self, simulation, state):
        if callable(self._scalar):
            values = np.asarray(self._scalar(simulation, state), dtype=np.float64)
            if values.shape != self._values.shape:
                raise ValueError(f"the scalar callable returned shape {values.shape}, "
                                 f"expected {self._values.shape}")
            self._values[:] = values
            return
        which = openmm.State.Forces if self._scalar == "force" else openmm.State.Velocities
        _copy_vectors(state, which, self._vectors)
        np.einsum("ij,ij->i", self._vectors, self._vectors, out=self._values)
        if self._scalar == "kinetic_energy":
            np.multiply(self._values, self._half_masses, out=self._values)
        else:
            np.sqrt(self._values, out=self._values)

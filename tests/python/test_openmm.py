"""lantern.openmm.Reporter on a real OpenMM simulation (examples/python/openmm_fluid.py: an argon
and xenon Lennard-Jones fluid on the Reference platform): every image equals a fresh render of the
State OpenMM handed over at that step, published through lantern.Context; the positions are
copied once per report into one buffer published once."""
import numpy as np
import openmm
import pytest
from openmm import unit

import lantern
import openmm_fluid
from lantern.openmm import Reporter

N_SIDE, EVERY, STEPS = 5, 100, 200


class Recorder:
    """A second reporter, through OpenMM's public API only: copies of what each State held."""

    def __init__(self, every, wrap):
        self.every, self.wrap, self.states = every, wrap, {}

    def describeNextReport(self, simulation):
        return (self.every - simulation.currentStep % self.every, True, True, True, False,
                self.wrap)

    def report(self, simulation, state):
        nm, ps = unit.nanometer, unit.picosecond
        self.states[simulation.currentStep] = {
            "position": np.array(state.getPositions(asNumpy=True).value_in_unit(nm)),
            "velocity": np.array(state.getVelocities(asNumpy=True).value_in_unit(nm / ps)),
            "force": np.array(state.getForces(asNumpy=True).value_in_unit(
                unit.kilojoule_per_mole / nm)),
            "time": state.getTime().value_in_unit(ps)}


def simulate(tmp_path, name, **options):
    """Runs the fluid with a Reporter (options) and a Recorder wrapping as the Reporter does."""
    simulation = openmm_fluid.build(N_SIDE)
    config = openmm_fluid.config(tmp_path / name, size=64)
    reporter = Reporter(config, EVERY, **options)
    recorder = Recorder(EVERY, options.get("wrap"))
    simulation.reporters += [reporter, recorder]
    pointers = []
    for _ in range(STEPS // EVERY):
        simulation.step(EVERY)
        pointers.append(reporter.context.published_pointers()["position"])
    reporter.close()
    return simulation, reporter, recorder, pointers


def fresh(tmp_path, name, step, **arrays):
    """The same scenes rendered from arrays published through lantern.Context."""
    directory = tmp_path / name
    with lantern.Context(openmm_fluid.config(directory, size=64)) as ctx:
        ctx.publish(**arrays)
        ctx.execute(step, 0.0)
    return {scene: (directory / f"{scene}_{step:06d}.png").read_bytes()
            for scene in ("element", "speed")}


def images(tmp_path, name, step):
    return {scene: (tmp_path / name / f"{scene}_{step:06d}.png").read_bytes()
            for scene in ("element", "speed")}


def expected_types(simulation, key):
    """Ar -> 0, Xe -> 1 (sorted labels), computed here from the topology."""
    labels = [key(atom) for atom in simulation.topology.atoms()]
    order = sorted(set(labels))
    return np.array([order.index(label) for label in labels], dtype=np.int32)


def test_images_equal_the_states_published_through_the_api(tmp_path):
    simulation, reporter, recorder, pointers = simulate(tmp_path, "reporter", scalar="speed")
    assert sorted(recorder.states) == [100, 200]
    edge = N_SIDE * 0.40
    assert all(((s["position"] >= 0) & (s["position"] < edge)).all()
               for s in recorder.states.values()), "OpenMM wraps periodic systems by default"
    types = expected_types(simulation, lambda atom: atom.element.symbol)
    assert reporter.type_names == ["Ar", "Xe"] and types.sum() == 25
    for step, state in recorder.states.items():
        speed = np.linalg.norm(state["velocity"], axis=1)
        reference = fresh(tmp_path, f"fresh{step}", step, position=state["position"],
                          type=types, scalar=speed)
        assert images(tmp_path, "reporter", step) == reference, f"step {step}"
    # The atoms moved: the two steps' images differ.
    assert images(tmp_path, "reporter", 100) != images(tmp_path, "reporter", 200)
    # One buffer, published once, overwritten in place at every report.
    assert pointers[0] == pointers[1] == reporter._positions.__array_interface__["data"][0]


def test_wrapping_forces_and_residue_types(tmp_path):
    """wrap=False: the unwrapped positions (some atoms left the box); scalar='force'; types by
    residue name."""
    simulation, reporter, recorder, _ = simulate(tmp_path, "unwrapped", wrap=False,
                                                  scalar="force", types="residue")
    state = recorder.states[200]
    edge = N_SIDE * 0.40
    assert ((state["position"] < 0) | (state["position"] > edge)).any(), "no atom left the box"
    types = expected_types(simulation, lambda atom: atom.residue.name)
    reference = fresh(tmp_path, "fresh", 200, position=state["position"], type=types,
                      scalar=np.linalg.norm(state["force"], axis=1))
    assert images(tmp_path, "unwrapped", 200) == reference


def test_kinetic_energy_and_a_callable(tmp_path):
    masses = None

    def kinetic(simulation, state):  # the same quantity, computed by the caller
        v = state.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
        return 0.5 * masses * (np.asarray(v) ** 2).sum(axis=1)

    _, _, recorder, _ = simulate(tmp_path, "builtin", scalar="kinetic_energy")
    simulation = openmm_fluid.build(N_SIDE)
    masses = np.array([simulation.system.getParticleMass(i).value_in_unit(unit.dalton)
                       for i in range(simulation.system.getNumParticles())])
    simulate(tmp_path, "callable", scalar=kinetic)
    assert images(tmp_path, "builtin", 200)["speed"] == images(tmp_path, "callable", 200)["speed"]
    assert images(tmp_path, "builtin", 200)["speed"] != \
        fresh(tmp_path, "by_speed", 200, position=recorder.states[200]["position"],
              scalar=np.linalg.norm(recorder.states[200]["velocity"], axis=1))["speed"]


def test_bad_arguments_name_what_is_wrong(tmp_path):
    config = openmm_fluid.config(tmp_path, size=16)
    with pytest.raises(ValueError, match="report_interval"):
        Reporter(config, 0)
    with pytest.raises(ValueError, match="types"):
        Reporter(config, 10, types="mass")
    with pytest.raises(ValueError, match="scalar"):
        Reporter(config, 10, scalar="pressure")
    with pytest.raises(lantern.Error, match="widht"):
        Reporter("scenes:\n  - widht: 10\n", 10)


def test_example_runs(tmp_path):
    simulation = openmm_fluid.run(str(tmp_path), n_side=4, steps=20, every=10, size=32)
    assert simulation.currentStep == 20
    assert sorted(p.name for p in tmp_path.glob("*.png")) == [
        "element_000010.png", "element_000020.png", "speed_000010.png", "speed_000020.png"]


def test_a_triclinic_box_reaches_the_dump_as_openmms_box_vectors(tmp_path):
    """OpenMM's reduced box vectors (a along x, b in the xy plane) are LAMMPS's restricted
    triclinic form: the H5MD dump records them as its edge matrix, row for row."""
    simulation = openmm_fluid.build(N_SIDE)
    edge = N_SIDE * 0.40
    a, b, c = (openmm.Vec3(edge, 0, 0), openmm.Vec3(0.3, edge, 0),
               openmm.Vec3(-0.2, 0.25, edge))
    simulation.system.setDefaultPeriodicBoxVectors(a, b, c)
    simulation.context.reinitialize(preserveState=True)
    simulation.context.setPeriodicBoxVectors(a, b, c)
    dump = tmp_path / "fluid.h5"
    config = openmm_fluid.config(tmp_path / "tri", size=32) + f"dump:\n  file: {dump}\n"
    reporter = Reporter(config, EVERY, scalar="speed")
    simulation.reporters.append(reporter)
    simulation.step(EVERY)
    reporter.close()
    import h5py
    with h5py.File(dump, "r") as f:
        edges = f["particles/all/box/edges/value"][0]
    want = np.array([[edge, 0, 0], [0.3, edge, 0], [-0.2, 0.25, edge]])
    assert edges.shape == (3, 3)
    assert np.allclose(edges, want, rtol=0, atol=1e-12), edges
    assert (tmp_path / "tri" / f"element_{EVERY:06d}.png").exists()

"""python3 -m lantern.render and lantern.render.render_universe on trajectories written here by
codes no one here wrote: LAMMPS text dumps (against lantern-render of the same file), OpenMM's DCD
and PDB (against the States OpenMM handed over), Lantern's own H5MD read by MDAnalysis (against
lantern-render). GROMACS's XTC, TRR and GRO are tested with lantern-imd in tests/imd."""
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import lantern

HERE = pathlib.Path(__file__).resolve().parent
SCENE = ("scenes:\n  - name: lj\n    width: 96\n    height: 72\n    radius: {radius}\n"
         "    camera: {{azimuth: 40, elevation: 25}}\n    color: {{by: {color}}}\n"
         "    output: {{pattern: '{directory}/lj_{{step:06d}}.png'}}\n{extra}")
LAMMPS_INPUT = """units lj
atom_style atomic
lattice fcc 0.8442
region box block 0 4 0 4 0 4
create_box 2 box
create_atoms 1 box
mass * 1.0
set type 1 type/fraction 2 0.3 4321
velocity all create 3.0 87287 loop geom
pair_style lj/cut 2.5
pair_coeff * * 1.0 1.0 2.5
fix 1 all nve
dump d all custom 10 traj.lammpstrj id type x y z vx vy vz
dump_modify d format float %.17g
run 40
"""
DUMP = ["--option", "format=LAMMPSDUMP", "--option", "topology_format=LAMMPSDUMP"]


def config(directory, color="type", radius=0.5, extra=""):
    return SCENE.format(directory=directory, color=color, radius=radius, extra=extra)


def cli(args, cwd, ranks=1, check=True):
    """python3 -m lantern.render ARGS (under mpiexec with ranks > 1); the finished process."""
    command = [sys.executable, "-m", "lantern.render", "--quiet", *map(str, args)]
    if ranks > 1:
        command = [*os.environ["LANTERN_MPIEXEC"].split(), "-n", str(ranks), *command]
    # Without the MPI variables of this process (an MPI singleton once a test rendered here):
    # a child mpiexec would take them for its own.
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=120, env=env)
    if check:
        assert done.returncode == 0, done.stderr
    return done


def images(directory):
    return {p.name: p.read_bytes() for p in sorted(pathlib.Path(directory).glob("*.png"))}


@pytest.fixture(scope="module")
def lammps_dump(tmp_path_factory):
    """A LAMMPS run's text dump (steps 0..40 every 10, full precision, with velocities)."""
    work = tmp_path_factory.mktemp("lammps")
    (work / "in.traj").write_text(LAMMPS_INPUT)
    subprocess.run([os.environ["LAMMPS_LMP"], "-in", "in.traj", "-log", "none", "-screen", "none"],
                   cwd=work, check=True, timeout=120)
    return work / "traj.lammpstrj"


def test_lammps_dump_equals_lantern_render(lammps_dump, tmp_path):
    """The selected frames (--frames 1:5 --every 2: steps 10 and 30), types as LAMMPS numbers
    them, drawn as lantern-render draws the same file (which parses it in double precision;
    MDAnalysis rounds to float32, which moves no pixel of this scene)."""
    (tmp_path / "viz.yaml").write_text(config(tmp_path / "mda"))
    cli([lammps_dump, lammps_dump, "-lantern", "viz.yaml", "--frames", "1:5", "--every", "2",
         *DUMP], tmp_path)  # the command itself, once
    (tmp_path / "ref.yaml").write_text(config(tmp_path / "ref"))
    subprocess.run([os.environ["LANTERN_RENDER"], "ref.yaml", str(lammps_dump), "--steps", "10,30"],
                   cwd=tmp_path, check=True, capture_output=True)
    got = images(tmp_path / "mda")
    assert sorted(got) == ["lj_000010.png", "lj_000030.png"]
    assert got == images(tmp_path / "ref")


def test_scalars_and_the_function(lammps_dump, tmp_path):
    """render_universe on a Universe: --scalar speed from the dump's velocities, and a topology
    attribute (masses) as the scalar; each equals a fresh render of what MDAnalysis read."""
    import MDAnalysis as mda
    from lantern.render import render_universe
    u = mda.Universe(str(lammps_dump), str(lammps_dump), format="LAMMPSDUMP",
                     topology_format="LAMMPSDUMP")
    count = render_universe(u, config(tmp_path / "speed", color="scalar"), frames="2:3",
                            scalar="speed", progress=False)
    assert count == 1
    ts = u.trajectory[2]
    speed = np.sqrt(np.sum(ts.velocities.astype(np.float64) ** 2, axis=1))
    with lantern.Context(config(tmp_path / "fresh", color="scalar")) as ctx:
        ctx.publish(position=ts.positions.copy(), type=u.atoms.types.astype(np.int32),
                    scalar=speed)
        ctx.execute(20, 0.0)
    assert images(tmp_path / "speed") == images(tmp_path / "fresh")
    assert render_universe(u, config(tmp_path / "mass", color="scalar"), frames="2:3",
                           scalar="masses", progress=False) == 1
    assert images(tmp_path / "mass") != images(tmp_path / "speed")


def test_bad_input_names_the_problem(lammps_dump, tmp_path, capsys):
    """Usage errors exit 2, bad input 1, each with a message naming what is wrong (run in this
    process: main() is what `python3 -m lantern.render` runs)."""
    from lantern.render import main
    (tmp_path / "viz.yaml").write_text(config(tmp_path / "out"))
    (tmp_path / "stats.yaml").write_text(config(tmp_path / "out", extra="stats: s.jsonl\n"))
    base = [str(lammps_dump), str(lammps_dump), "--quiet"]
    with pytest.raises(SystemExit) as caught:
        main([*base, "-lantern", "viz.yaml", "--frames", "x"])
    assert caught.value.code == 2 and "--frames 'x'" in capsys.readouterr().err
    for args, message in (
            (["--scalar", "charges", *DUMP], "scalar 'charges'"),
            (["--types", "element", *DUMP], "types='element': the topology has no elements"),
            (["--scalar", "force", *DUMP], "scalar 'force': frame 0 has no forces"),
            ([], "isn't a valid topology format"),  # MDAnalysis does not guess .lammpstrj
            (["--split", "frames", *DUMP], "--split frames: each rank renders its own frames, "
                                          "so one stats file cannot be written")):
        yaml = "stats.yaml" if "frames" in args else "viz.yaml"
        assert main([*base, "-lantern", str(tmp_path / yaml), *args]) == 1
        err = capsys.readouterr().err
        assert message in err, err
    assert main([str(tmp_path / "none.gro"), "-lantern", "viz.yaml"]) == 1
    assert "No such file" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # nothing rendered


def test_h5md_from_lanterns_dump(lammps_dump, tmp_path):
    """Lantern's own float32 H5MD dump read by MDAnalysis (topology: the LAMMPS dump) draws what
    lantern-render draws from it."""
    import MDAnalysis as mda
    u = mda.Universe(str(lammps_dump), str(lammps_dump), format="LAMMPSDUMP",
                     topology_format="LAMMPSDUMP")
    dump = f"dump: {{file: '{tmp_path}/atoms.h5', fields: [position, type, id], " \
           "precision: float32}\n"
    with lantern.Context(config(tmp_path / "unused", extra=dump)) as ctx:
        for ts in u.trajectory:
            ctx.publish(position=ts.positions.astype(np.float64),
                        type=u.atoms.types.astype(np.int32), id=u.atoms.ids)
            ctx.execute(ts.data["step"], 0.0)
    from lantern.render import main
    (tmp_path / "viz.yaml").write_text(config(tmp_path / "mda"))
    assert main([str(lammps_dump), str(tmp_path / "atoms.h5"), "-lantern",
                 str(tmp_path / "viz.yaml"), "--quiet", "--option", "topology_format=LAMMPSDUMP",
                 "--option", "format=H5MD", "--option", "convert_units=False"]) == 0
    (tmp_path / "ref.yaml").write_text(config(tmp_path / "ref"))
    subprocess.run([os.environ["LANTERN_RENDER"], "ref.yaml", str(tmp_path / "atoms.h5")],
                   cwd=tmp_path, check=True, capture_output=True)
    assert len(images(tmp_path / "mda")) == 5
    assert images(tmp_path / "mda") == images(tmp_path / "ref")


def test_openmm_dcd_and_pdb(tmp_path):
    """OpenMM writes a PDB (topology) and a DCD (Angstrom, float32); the images equal the States
    OpenMM handed over, converted as OpenMM's DCD writer converts them. MDAnalysis numbers DCD
    frames' steps 1, 2, ... (the file's frame counter), so the images are named by those."""
    import openmm.app as app

    import openmm_fluid
    from test_openmm import Recorder
    simulation = openmm_fluid.build(5)
    state = simulation.context.getState(getPositions=True)
    with open(tmp_path / "start.pdb", "w") as f:
        app.PDBFile.writeFile(simulation.topology, state.getPositions(), f)
    recorder = Recorder(10, True)
    simulation.reporters += [app.DCDReporter(str(tmp_path / "traj.dcd"), 10), recorder]
    simulation.step(20)
    del simulation  # closes the DCD file
    from lantern.render import main
    (tmp_path / "viz.yaml").write_text(config(tmp_path / "mda", radius=1.7))
    assert main([str(tmp_path / "start.pdb"), str(tmp_path / "traj.dcd"), "--quiet",
                 "-lantern", str(tmp_path / "viz.yaml")]) == 0
    types = np.array([0 if atom.element.symbol == "Ar" else 1
                      for atom in app.PDBFile(str(tmp_path / "start.pdb")).topology.atoms()],
                     dtype=np.int32)
    for frame, step in enumerate((10, 20), start=1):
        angstrom = (10 * recorder.states[step]["position"]).astype(np.float32)  # as DCDFile
        with lantern.Context(config(tmp_path / "fresh", radius=1.7)) as ctx:
            ctx.publish(position=angstrom, type=types)
            ctx.execute(frame, 0.0)
    assert sorted(images(tmp_path / "mda")) == ["lj_000001.png", "lj_000002.png"]
    assert images(tmp_path / "mda") == images(tmp_path / "fresh")


def test_ranks_split_atoms_or_frames(lammps_dump, tmp_path):
    """mpiexec -n 2: atoms split (each rank a share of every frame) and frames split (each rank
    its own frames) give the 1-rank images."""
    from lantern.render import main
    import json
    results = {}
    for name, ranks, split in (("one", 1, "atoms"), ("atoms", 2, "atoms"),
                               ("frames", 2, "frames")):
        stats = f"stats: {tmp_path}/atoms.jsonl\n" if name == "atoms" else ""
        (tmp_path / f"{name}.yaml").write_text(config(tmp_path / name, extra=stats))
        args = [lammps_dump, lammps_dump, "-lantern", tmp_path / f"{name}.yaml", "--split", split,
                *DUMP]
        if ranks == 1:
            assert main([*map(str, args), "--quiet"]) == 0
        else:
            cli(args, tmp_path, ranks=ranks)
        results[name] = images(tmp_path / name)
    assert len(results["one"]) == 5
    assert results["atoms"] == results["one"] == results["frames"]
    # Atoms split: each rank published its half of the 256 atoms, not all of them.
    for line in (tmp_path / "atoms.jsonl").read_text().splitlines():
        stats = json.loads(line)
        assert stats["ranks"] == 2 and stats["particles"]["finite"] == 256
        assert stats["scenes"][0]["per_rank"]["drawn"]["max"] == 128


def test_selection_example(lammps_dump, tmp_path):
    """examples/python/render_selection.py: an AtomGroup (LAMMPS type 2) draws what publishing
    those atoms' positions draws."""
    import MDAnalysis as mda
    import render_selection
    assert render_selection.main(str(lammps_dump), str(lammps_dump), "type 2",
                                 str(tmp_path / "example")) == 5
    u = mda.Universe(str(lammps_dump), str(lammps_dump), format="LAMMPSDUMP",
                     topology_format="LAMMPSDUMP")
    atoms = u.select_atoms("type 2")
    assert 0 < len(atoms) < len(u.atoms)
    ts = u.trajectory[4]
    with lantern.Context(render_selection.config(tmp_path / "fresh")) as ctx:
        ctx.publish(position=atoms.positions, type=np.full(len(atoms), 2, dtype=np.int32))
        ctx.execute(ts.data["step"], 0.0)
    assert (tmp_path / "example" / "selection_000040.png").read_bytes() == \
        (tmp_path / "fresh" / "selection_000040.png").read_bytes()


def test_a_triclinic_universe_gives_its_reduced_box_vectors(tmp_path):
    """MDAnalysis dimensions with angles other than 90 degrees: the box is triclinic, its edge
    vectors MDAnalysis's own reduced ones (a along x, b in the xy plane), recorded as the H5MD
    dump's edge matrix; at 90 degrees the dump records the three lengths."""
    import h5py
    import MDAnalysis as mda
    from MDAnalysis.lib.mdamath import triclinic_vectors
    from lantern.render import render_universe
    for name, dims in (("tilted", [12.0, 11.0, 10.0, 80.0, 95.0, 70.0]),
                       ("upright", [12.0, 11.0, 10.0, 90.0, 90.0, 90.0])):
        u = mda.Universe.empty(64, atom_resindex=np.zeros(64, dtype=int), trajectory=True)
        grid = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
        u.atoms.positions = (grid * 2.5 + 1.0).astype(np.float32)
        u.dimensions = np.array(dims, dtype=np.float32)
        dump = tmp_path / f"{name}.h5"
        extra = f"dump:\n  file: {dump}\n"
        assert render_universe(u, config(tmp_path / name, color="solid") + extra, types="none",
                               progress=False) == 1
        with h5py.File(dump, "r") as f:
            edges = f["particles/all/box/edges/value"][0]
        if name == "tilted":
            assert edges.shape == (3, 3)
            assert np.allclose(edges, triclinic_vectors(u.dimensions), atol=1e-5), edges
        else:
            assert np.allclose(edges, dims[:3]), edges

"""Context.publish(bonds=..., bond_type=..., ghost_count=...): the bond list is borrowed in place
as two strided columns, every layout gives the same image, ghosts are bond ends only, and bad
bonds are refused naming the bond."""
import numpy as np
import pytest

import lantern
from conftest import png_pixels


def address(a):
    return a.__array_interface__["data"][0]


def bond_config(directory, size=48, bonds="{radius: 0.2}"):
    """A camera looking down z at atoms along x in [0, 4]; a scene with a bonds: section."""
    return (f"gl: none\nscenes:\n  - width: {size}\n    height: {size}\n    radius: 0.4\n"
            f"    color: {{by: type}}\n    bonds: {bonds}\n"
            f"    camera: {{position: [2, 0, 10], look_at: [2, 0, 0], up: [0, 1, 0], fov: 30}}\n"
            f"    output: {{pattern: '{directory}/frame_{{step:06d}}.png'}}\n")


def chain():
    """Three atoms 2 apart along x (bonds far longer than the spheres' radius 0.4), ids 10..12."""
    x = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [4.0, 0.0, 0.0]])
    return x, np.array([1, 2, 3], dtype=np.int32), np.array([10, 11, 12], dtype=np.int64)


class BondRenderer:
    def __init__(self, tmp_path):
        self.tmp_path, self.count = tmp_path, 0

    def __call__(self, bonds_section="{radius: 0.2}", **arrays):
        self.count += 1
        directory = self.tmp_path / f"render{self.count}"
        with lantern.Context(bond_config(directory, bonds=bonds_section)) as ctx:
            ctx.publish(**arrays)
            ctx.execute(0, 0.0)
        return (directory / "frame_000000.png").read_bytes()


@pytest.fixture
def render(tmp_path):
    return BondRenderer(tmp_path)


def test_bond_columns_are_borrowed_not_copied(tmp_path):
    x, t, i = chain()
    b = np.array([[0, 1], [1, 2]], dtype=np.int64)
    bt = np.array([1, 2], dtype=np.int32)
    with lantern.Context(bond_config(tmp_path)) as ctx:
        ctx.publish(position=x, type=t, bonds=b, bond_type=bt)
        pointers = ctx.published_pointers()
    assert pointers["bonds.first"] == address(b)
    assert pointers["bonds.second"] == address(b) + 8
    assert pointers["bond_type"] == address(bt)


def gaps(row, background):
    """The runs of background pixels between drawn ones along an image row: [(first, last)]."""
    drawn = [c for c in range(len(row)) if (row[c] != background).any()]
    return [(a + 1, b - 1) for a, b in zip(drawn, drawn[1:]) if b > a + 1]


def test_bonds_are_drawn_between_the_atoms(render):
    x, t, _ = chain()
    plain = png_pixels(render(position=x, type=t))
    bonded = png_pixels(render(position=x, type=t, bonds=np.array([[0, 1]])))
    background = plain[0, 0]
    centre = plain.shape[0] // 2
    # Along the row through the atoms, the three spheres leave two gaps; the bond fills the first
    # (atoms 0 and 1) completely and leaves the second (atoms 1 and 2, not bonded) empty.
    (a0, a1), (b0, b1) = gaps(plain[centre], background)
    assert (bonded[centre, a0:a1 + 1] != background).any(axis=1).all(), "the bond has holes"
    assert (bonded[centre, b0:b1 + 1] == plain[centre, b0:b1 + 1]).all()
    # Across the bond at its midpoint it is thinner than the spheres (radius 0.2 against 0.4).
    mid = (a0 + a1) // 2
    across = int((bonded[:, mid] != background).any(axis=1).sum())
    sphere = int((plain[:, (a1 + b0) // 2] != background).any(axis=1).sum())  # atom 1
    assert 0 < across < sphere
    assert abs(across / sphere - 0.5) < 0.2, (across, sphere)


def test_every_layout_of_the_bond_list_gives_the_same_image(render):
    x, t, _ = chain()
    b = np.array([[0, 1], [2, 1]], dtype=np.int64)
    reference = render(position=x, type=t, bonds=b)
    wide = np.zeros((4, 5), dtype=np.int32)  # every other row, columns 1 and 3
    wide[::2, 1], wide[::2, 3] = b[:, 0], b[:, 1]
    assert render(position=x, type=t, bonds=b.astype(np.int32)) == reference
    assert render(position=x, type=t, bonds=np.asfortranarray(b)) == reference
    assert render(position=x, type=t, bonds=wide[::2, 1::2]) == reference
    assert render(position=x, type=t, bonds=b[:, ::-1].copy()) == reference  # either order


def test_bond_type_colors_bonds_by_type(render):
    x, t, _ = chain()
    b = np.array([[0, 1], [1, 2]])
    section = "{radius: 0.2, color: by_type, palette: [[1, 0, 0], [0, 0, 1]]}"
    same = render(section, position=x, type=t, bonds=b, bond_type=np.array([0, 0]))
    mixed = render(section, position=x, type=t, bonds=b, bond_type=np.array([0, 1]))
    assert same != mixed
    pixels = png_pixels(mixed)
    centre = pixels.shape[0] // 2
    row = pixels[centre, :, :3].astype(int)
    assert ((row[:, 0] > 100) & (row[:, 2] < 50)).any(), "a red bond (type 0)"
    assert ((row[:, 2] > 100) & (row[:, 0] < 50)).any(), "a blue bond (type 1)"


def test_ghosts_are_bond_ends_only(render):
    x, t, i = chain()
    owned = render(position=x[:2], type=t[:2], id=i[:2])
    # Atom 2 as a ghost without bonds: not drawn, the image of the owned atoms alone.
    assert render(position=x, type=t, id=i, ghost_count=1) == owned
    # Bonded to atom 1, its half is drawn (listed once, here), its sphere still is not.
    to_ghost = render(position=x, type=t, id=i, ghost_count=1, bonds=np.array([[1, 2]]))
    to_owned = render(position=x, type=t, id=i, bonds=np.array([[1, 2]]))
    assert to_ghost not in (owned, to_owned)
    # Listed by both ranks, this rank draws only its own atom's half: less than listed once.
    by_both = render(position=x, type=t, id=i, ghost_count=1, bonds=np.array([[1, 2]]),
                     bonds_listed="by_both")
    assert by_both not in (owned, to_ghost)
    background = png_pixels(owned)[0, 0]
    drawn = lambda image: int((png_pixels(image) != background).any(axis=2).sum())
    assert drawn(owned) < drawn(by_both) < drawn(to_ghost)


@pytest.mark.parametrize("arrays, match", [
    (dict(bonds=np.array([[0, 3]])), r"bonds.second\[0\]: 3 is not below"),
    (dict(bonds=np.array([[0, 1], [1, 1]])), r"bonds.*\[1\].*itself"),
    (dict(bonds=np.array([[-1, 1]])), r"bonds.first\[0\]"),
])
def test_bad_bonds_are_refused_naming_the_bond(tmp_path, arrays, match):
    x, t, i = chain()
    with lantern.Context(bond_config(tmp_path)) as ctx:
        with pytest.raises(lantern.Error, match=match) as error:
            ctx.publish(position=x, type=t, **arrays)
        assert error.value.status == lantern.ERR_INVALID_ARGUMENT
        ctx.execute(0, 0.0)  # the particles are still drawn
    assert (tmp_path / "frame_000000.png").exists()


def test_ghosts_without_ids_are_refused(tmp_path):
    x, t, _ = chain()
    with lantern.Context(bond_config(tmp_path)) as ctx:
        with pytest.raises(lantern.Error, match="ghost"):
            ctx.publish(position=x, type=t, ghost_count=1, bonds=np.array([[1, 2]]))


@pytest.mark.parametrize("arrays, match", [
    (dict(bonds=np.array([0, 1])), r"bonds: shape \(2,\) is not \(m, 2\)"),
    (dict(bonds=np.array([[0.0, 1.0]])), r"bonds: dtype float64"),
    (dict(bonds=np.array([[0, 1]]), bond_type=np.array([1, 2])), r"bond_type: shape \(2,\)"),
    (dict(bond_type=np.array([1])), r"bond_type: given without bonds"),
    (dict(ghost_count=4), r"ghost_count: 4 ghosts, but the arrays hold only 3"),
    (dict(ghost_count=-1), r"ghost_count: -1 is negative"),
    (dict(bonds=np.array([[0, 1]]), bonds_listed="twice"), r"bonds_listed: 'twice'"),
])
def test_bond_arrays_that_cannot_be_borrowed_are_refused(tmp_path, arrays, match):
    x, t, i = chain()
    with lantern.Context(bond_config(tmp_path)) as ctx:
        with pytest.raises(ValueError, match=match):
            ctx.publish(position=x, type=t, id=i, **arrays)

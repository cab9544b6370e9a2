"""Robot models: IK, det(A) against the seed 003 closed form, Annex C vertex signs, file errors."""
from decimal import Decimal
from fractions import Fraction
from pathlib import Path
import re
import subprocess
import sys
import tomllib

import numpy as np
import pytest
import sympy as sp

from certkin import InputError, RobotFileError, load_robot, robot_from_dict
from certkin.robots import Planar3RPR
from certkin.robots.files import MAX_FILE_BYTES, READ_CHUNK, robot_file_bytes
from certkin.robots.poses import parse_box, parse_lengths, parse_pose
from intervals import Interval

DATA = Path(__file__).parent / "data"
EXAMPLES = Path(__file__).parent.parent / "examples" / "robots"

# seed 003, Table 3.9 (planar Example 2) and Table 3.8 (Example 1)
EX2 = {"name": "ex2", "kind": "planar-3rpr",
       "base": [["3.78", "4.34"], ["34.47", "-3.78"], ["16.233", "34.76"]],
       "platform": [["-4.83", "-3.19"], ["12.04", "-3.19"], ["8.23", "12.09"]]}
EX1 = {"name": "ex1", "kind": "planar-3rpr",
       "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
       "platform": [["0", "0"], ["17.04", "0"], ["13.2364", "16.097"]]}


def annex_b_closed_form(corrected: bool):
    """det J of seed 003 eq. (3.4)-(3.5) with the Annex B.1 coefficients, as a sympy expression."""
    (x, y, phi), g = Planar3RPR.symbols()
    names = {str(s): s for s in g}
    N = {}
    for line in (DATA / "seed003_annex_b.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        k, e = line.split("=", 1)
        N[int(k.strip()[1:])] = sp.sympify(e, locals=names)
    if corrected:  # digest: the last term of N13 is b1y p1y p3y, not b1y p1y p3x
        N[13] += names["b1y"] * names["p1y"] * (names["p3y"] - names["p3x"])
    c, s = sp.cos(phi), sp.sin(phi)
    E1, E2, E3 = N[1] * c + N[2] * s, N[3] * c + N[4] * s, N[5] * c + N[6] * s
    E4 = N[7] * c**2 + N[8] * s**2 + N[9] * s * c + N[10] * c + N[11] * s
    E5 = N[12] * c**2 + N[13] * s**2 + N[14] * s * c + N[15] * c + N[16] * s
    E6 = (N[17] * c**3 + N[18] * s**3 + N[19] * s * c**2 + N[20] * s**2 * c + N[21] * c**2
          + N[22] * s**2 + N[23] * s * c + N[24] * c + N[25] * s)
    return E1 * x**2 + E2 * y**2 + E3 * x * y + E4 * x + E5 * y + E6


def _poly(expr):
    (x, y, phi), _ = Planar3RPR.symbols()
    C, S = sp.symbols("C S")
    return sp.expand(expr.subs({sp.cos(phi): C, sp.sin(phi): S}))


def test_planar_det_equals_annex_b_closed_form_with_n13_corrected():
    det = Planar3RPR.symbolic_model()["det"]
    assert _poly(annex_b_closed_form(corrected=True) - det) == 0
    # the printed N13 is wrong: the difference is exactly the typo term
    assert _poly(annex_b_closed_form(corrected=False) - det) != 0


def _exact_closed_form(data, pose):
    """det J at a pose by the corrected closed form, exactly (sympy rationals, exact cos/sin)."""
    (x, y, phi), g = Planar3RPR.symbols()
    vals = [Fraction(v) for p in data["base"] + data["platform"] for v in p]
    expr = annex_b_closed_form(corrected=True).subs(dict(zip(g, [sp.Rational(v.numerator, v.denominator) for v in vals])))
    return expr.subs({x: pose[0], y: pose[1], phi: pose[2]})


@pytest.mark.parametrize("data,signs", [(EX2, [1, -1, -1, -1, 1, -1, 1, -1]), (EX1, [1, -1, 1, 1, 1, -1, 1, -1])])
def test_annex_c_vertex_signs(data, signs):
    """Annex C.1 prints the vertex signs of Example 2; vertices in (x, y, phi) lexicographic order."""
    robot = robot_from_dict(data)
    verts = [(x, y, p) for x in (-50, 50) for y in (-50, 50) for p in (0, sp.pi / 4)] if data is EX2 else \
            [(x, y, p) for x in (-20, 20) for y in (-20, 20) for p in (0, sp.pi / 4)]
    exact = [sp.sign(sp.nsimplify(_exact_closed_form(data, v))) for v in verts]
    assert exact == signs
    pi4 = robot.pose_box(["0", "0", "45deg"])[2]
    boxes = Interval(np.array([[float(v[0]), float(v[1]), 0.0 if v[2] == 0 else float(pi4.lo)] for v in verts]),
                     np.array([[float(v[0]), float(v[1]), 0.0 if v[2] == 0 else float(pi4.hi)] for v in verts]))
    det = robot.det_enclosure(boxes)
    got = np.where(det.lo > 0, 1, np.where(det.hi < 0, -1, 0))
    assert list(got) == signs


def test_annex_c2_rectangle_vertices_all_negative():
    robot = robot_from_dict(EX2)
    verts = [(x, y) for x in (-50, 50) for y in (-50, 50)]
    exact = [sp.sign(sp.nsimplify(_exact_closed_form(EX2, (x, y, sp.pi / 4)))) for x, y in verts]
    assert exact == [-1, -1, -1, -1]
    pi4 = robot.pose_box(["0", "0", "45deg"])[2]
    det = robot.det_enclosure(Interval(np.array([[x, y, pi4.lo] for x, y in verts], dtype=float),
                                       np.array([[x, y, pi4.hi] for x, y in verts], dtype=float)))
    assert np.all(det.hi < 0)


def test_det_enclosure_contains_exact_value_at_rational_points():
    robot = robot_from_dict(EX2)
    for pose in [(0, 0, 0), (10, 10, 0), (-7, 3, 0)]:
        exact = _exact_closed_form(EX2, pose)
        det = robot.det_enclosure(Interval(np.array(pose, dtype=float)))
        assert Fraction(float(det.lo)) <= Fraction(str(sp.Rational(exact))) <= Fraction(float(det.hi))
    assert abs(float(_exact_closed_form(EX2, (0, 0, 0))) - 28891.66058) < 1e-4  # digest §3.6 spot value


def test_inverse_kinematics_against_numpy():
    rng = np.random.default_rng(3)
    robot = robot_from_dict(EX2)
    b = np.array([[float(c) for c in p] for p in EX2["base"]])
    p = np.array([[float(c) for c in q] for q in EX2["platform"]])
    for _ in range(20):
        x, y, phi = rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(-np.pi, np.pi)
        R = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
        expected = np.linalg.norm(np.array([x, y]) + p @ R.T - b, axis=1)
        enc = robot.leg_lengths(Interval(np.array([x, y, phi])))
        assert np.all(enc.lo <= expected + 1e-9 * expected) and np.all(expected - 1e-9 * expected <= enc.hi)
        assert np.all(enc.hi - enc.lo < 1e-9)
        assert np.allclose(robot.leg_lengths_float([x, y, phi]), expected)


def _rz(a):
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


def _rx(a):
    return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])


def _ry(a):
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def test_gough_ik_and_det_against_numpy():
    rng = np.random.default_rng(5)
    base = rng.uniform(-10, 10, size=(6, 3)).round(3)
    base[:, 2] = 0
    plat = rng.uniform(-5, 5, size=(6, 3)).round(3)
    plat[:, 2] = 0
    robot = robot_from_dict({"kind": "gough-stewart", "base": [[str(c) for c in r] for r in base],
                             "platform": [[str(c) for c in r] for r in plat]})
    for _ in range(5):
        pose = np.array([*rng.uniform(-2, 2, 2), rng.uniform(8, 12), *rng.uniform(-0.5, 0.5, 3)])
        R = _rz(pose[3]) @ _rx(pose[4]) @ _rz(pose[5])
        rb = plat @ R.T
        legs = pose[:3] + rb - base
        A = np.hstack([legs, np.cross(rb, legs)])
        enc = robot.leg_lengths(Interval(pose))
        assert np.allclose((enc.lo + enc.hi) / 2, np.linalg.norm(legs, axis=1), rtol=1e-12)
        det = robot.det_enclosure(Interval(pose))
        assert float(det.lo) <= np.linalg.det(A) * (1 + 1e-9) + 1e-9 and np.linalg.det(A) * (1 - 1e-9) - 1e-9 <= float(det.hi) \
            or float(det.lo) <= np.linalg.det(A) <= float(det.hi)


def test_spherical_matches_seed003_tilt_torsion_reference():
    """Seed 003 Example 3 (Table 4.15): det J at T&T (0, pi/4, 0) is -0.0576 (digest §3.6)."""
    w1, w2, w3, u2, u3, x1, x2, x3, y2, y3, h = ["1.6", "-1.1", "-0.9", "1.2", "-1", "1", "-0.8", "-0.1", "0", "-0.5", "1.5"]
    robot = robot_from_dict({"kind": "spherical-3dof",
                             "base": [[w1, "0", "-" + h], [w2, u2, "-" + h], [w3, u3, "-" + h]],
                             "platform": [[x1, "0", "0"], [x2, y2, "0"], [x3, y3, "0"]]})
    # T&T (phi1, phi2, sigma) = Euler (phi1, phi2, sigma - phi1)
    box = robot.pose_box(["0", "45deg", "0"])
    det = robot.det_enclosure(box)
    assert float(det.lo) <= -0.0576 + 1e-12 and -0.0576 - 1e-12 <= float(det.hi)
    # independent numpy evaluation at a random pose
    rng = np.random.default_rng(2)
    a = np.array([[1.6, 0, -1.5], [-1.1, 1.2, -1.5], [-0.9, -1, -1.5]])
    b = np.array([[1, 0, 0], [-0.8, 0, 0], [-0.1, -0.5, 0]])
    for _ in range(5):
        e = rng.uniform(-1.5, 1.5, 3)
        Q = _rz(e[0]) @ _ry(e[1]) @ _rz(e[2])
        A = np.cross(a, b @ Q.T)
        det = robot.det_enclosure(Interval(e))
        assert abs((float(det.lo) + float(det.hi)) / 2 - np.linalg.det(A)) < 1e-12


@pytest.mark.parametrize("mutate,field", [
    (lambda d: d.pop("base"), "base"),
    (lambda d: d.__setitem__("kind", "delta"), "kind"),
    (lambda d: d["base"].pop(), "base"),
    (lambda d: d["base"][1].__setitem__(0, "abc"), "base[1][0]"),
    (lambda d: d["base"][1].__setitem__(0, Decimal("NaN")), "base[1][0]"),
    (lambda d: d["base"][1].__setitem__(0, Decimal("Infinity")), "base[1][0]"),
    (lambda d: d["platform"][2].append("1"), "platform[2]"),
    (lambda d: d.__setitem__("platform", [["1", "1"]] * 3), "platform"),
    (lambda d: d.__setitem__("limits", {"leg_length": [["5", "3"], ["1", "2"], ["1", "2"]]}), "limits.leg_length[0]"),
    (lambda d: d.__setitem__("limits", {"leg_width": 3}), "limits.leg_width"),
    (lambda d: d.__setitem__("colour", "red"), "colour"),
])
def test_bad_robot_data_names_the_field(mutate, field):
    data = {k: (v if not isinstance(v, list) else [list(p) for p in v]) for k, v in EX2.items()}
    mutate(data)
    with pytest.raises(RobotFileError) as err:
        robot_from_dict(data, "bad.toml")
    assert err.value.field == field
    assert str(err.value).startswith("bad.toml: ")


def test_bad_files(tmp_path):
    p = tmp_path / "broken.toml"
    p.write_text("kind = [unclosed")
    with pytest.raises(RobotFileError, match="broken.toml: not valid TOML"):
        load_robot(p)
    with pytest.raises(RobotFileError, match="no such file"):
        load_robot(tmp_path / "missing.toml")



def test_a_robot_file_that_starts_with_a_byte_order_mark_loads(tmp_path):
    """A file saved by a Windows editor starts with a UTF-8 BOM: it was 'not valid TOML'."""
    source = EXAMPLES / "seed003-planar-example-2.toml"
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + source.read_bytes())
    assert load_robot(path).to_dict() == load_robot(source).to_dict()


def test_decimals_of_more_than_1000_digits_are_refused_naming_the_field(tmp_path):
    """A 4400-digit decimal raised "ValueError: Exceeds the limit (4300 digits)" (``Fraction`` of its text), a
    4400-digit integer the same in tomllib; 1000 digits are taken (a certificate's checker reads them)."""
    many = "12." + "0" * 4400
    data = {"kind": "planar-3rpr", "base": [["0", "0"], ["10", "0"], ["3", "10"]],
            "platform": [["0", "0"], [Decimal(many), "0"], ["2", "2"]]}
    with pytest.raises(RobotFileError, match=r"^r\.toml: platform\[1\]\[0\]: a decimal of more than 1000 digits"):
        robot_from_dict(data, "r.toml")
    with pytest.raises(RobotFileError, match=r"^r\.toml: home\[2\]: a decimal of more than 1000 digits"):
        robot_from_dict({**data, "platform": [["0", "0"], ["4", "0"], ["2", "2"]], "home": [0, 0, many + "deg"]},
                        "r.toml")
    p = tmp_path / "r.toml"
    p.write_text(f'kind = "planar-3rpr"\nbase = [[0, 0], [10, 0], [3, 10]]\nplatform = [[0, 0], [{many}, 0], [2, 2]]\n')
    with pytest.raises(RobotFileError, match=r"r\.toml: platform\[1\]\[0\]: a decimal of more than 1000 digits"):
        load_robot(p)
    p.write_text(f'kind = "planar-3rpr"\nbase = [[0, 0], [1{"0" * 4400}, 0], [3, 10]]\n')
    with pytest.raises(RobotFileError, match=r"r\.toml: not a robot file \(an integer of more than 4300 digits\)"):
        load_robot(p)
    p.write_text(f'kind = "planar-3rpr"\nbase = [[0, 0], [10, 0], [3, 10]]\nplatform = [[0, 0], [4.{"0" * 998}, 0], [2, 2]]\n')
    assert load_robot(p).platform[1][0] == "4." + "0" * 998


def test_values_in_messages_are_plain_and_short():
    """``base[0]: expected 2 coordinates, got [Decimal('3.78'), ...]`` showed Python's repr; a 100 000-character
    value was echoed whole.  Values are shown plain, long ones by their start and end."""
    from certkin.errors import clip, shown
    data = {"kind": "planar-3rpr", "base": [[Decimal("3.78"), Decimal("4.34"), 1], ["10", "0"], ["3", "10"]],
            "platform": [["0", "0"], ["4", "0"], ["2", "2"]]}
    with pytest.raises(RobotFileError) as err:
        robot_from_dict(data, "r.toml")
    assert str(err.value) == "r.toml: base[0]: expected 2 coordinates, got [3.78, 4.34, 1]"
    data["base"][0] = ["3.78", "4.34"]
    with pytest.raises(RobotFileError) as err:
        robot_from_dict({**data, "limits": {"leg_length": [[Decimal("1.5"), 2, 3]] * 3}}, "r.toml")
    assert str(err.value) == "r.toml: limits.leg_length[0]: expected [min, max], got [1.5, 2, 3]"
    with pytest.raises(RobotFileError) as err:
        robot_from_dict({**data, "home": ["a" * 50000 + "b" * 50000, 0, 0]}, "r.toml")
    assert str(err.value) == ("r.toml: home[0]: not a plain decimal number: '" + "a" * 28 + "..." + "b" * 27 + "' "
                              "(digits 0-9, '.', 'e', a sign)")
    nested = []
    for _ in range(100000):
        nested = [nested]
    assert shown(nested) == "[" * 29 + "..." + "]" * 28
    assert shown({"x": [None, True, Fraction(1, 3)]}) == "{'x': [nothing, true, 1/3]}"
    assert clip("x" * 60) == "x" * 60 and len(clip("x" * 61)) == 60


@pytest.mark.parametrize("nested", ["[" * 100000 + "]" * 100000, "{a = " * 100000 + "}" * 100000])
def test_arrays_or_tables_nested_too_deeply_are_refused_naming_the_file(tmp_path, nested):
    """tomllib recurses once per level: a file of 100 000 nested arrays raised RecursionError."""
    p = tmp_path / "deep.toml"
    p.write_text(f'kind = "planar-3rpr"\nbase = {nested}\nplatform = [[0, 0], [4, 0], [2, 2]]\n')
    with pytest.raises(RobotFileError, match=r"deep\.toml: not a robot file \(arrays or tables nested too deeply\)"):
        load_robot(p)


def test_every_bundled_robot_loads_and_round_trips():
    files = sorted(EXAMPLES.glob("*.toml"))
    assert len(files) >= 10
    for f in files:
        robot = load_robot(f)
        again = robot_from_dict(robot.to_dict() | ({"home": robot.home} if robot.home else {}), str(f))
        assert again.to_dict() == robot.to_dict()
        assert again.geometry_texts() == robot.geometry_texts()
        # exact decimals survive: each enclosure contains the decimal text
        for t, iv in zip(robot.geometry_texts(), robot.parameters):
            assert Fraction(float(iv.lo)) <= Fraction(t) <= Fraction(float(iv.hi))


@pytest.mark.parametrize("path", sorted(Path(__file__).resolve().parents[1].glob("examples/robots/*.toml")))
def test_float_helpers_match_the_symbolic_model(path):
    """The numpy float formulas (leg vectors, A, rotation) agree with the sympy model lambdified."""
    robots = [load_robot(path)]
    if robots[0].kind == "spherical-3dof":
        robots.append(robots[0].with_angles("tilt-torsion"))
    rng = np.random.default_rng(1)
    for robot in robots:
        pose_syms, geom_syms = robot.symbols()
        model = robot.symbolic_model()
        g = [float(Fraction(t)) for t in robot.geometry_texts()]
        poses = rng.uniform(-1, 1, size=(5, len(robot.pose_names)))
        args = list(pose_syms) + list(geom_syms)
        legs = sp.lambdify(args, [list(leg) for leg in model["legs"]], "math")
        A = sp.lambdify(args, model["A"].tolist(), "math")
        for pose in poses:
            values = list(pose) + g
            np.testing.assert_allclose(robot.leg_vectors_float(pose), np.array(legs(*values), dtype=float),
                                       rtol=1e-12, atol=1e-9)
            np.testing.assert_allclose(robot.jacobian_float(pose), np.array(A(*values), dtype=float),
                                       rtol=1e-12, atol=1e-9 * max(1.0, np.max(np.abs(g))) ** 2)
            if "R" in model:
                R = sp.lambdify(args, model["R"].tolist(), "math")
                np.testing.assert_allclose(robot.rotation_float(pose), np.array(R(*values), dtype=float), atol=1e-14)
        assert robot.leg_lengths_float(poses).shape == (5, robot.n_legs)


def test_loading_a_robot_does_not_import_sympy():
    """Robot files, poses and forward kinematics need no symbolic model (sympy costs ~0.5 s a process)."""
    code = ("import sys, certkin; r = certkin.load_robot('examples/robots/seed003-planar-example-2.toml'); "
            "r.det_float([[0.0, 0.0, 0.1]]); print('sympy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=Path(__file__).resolve().parents[1])
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


def test_a_robot_file_is_read_up_to_one_byte_past_the_limit(tmp_path):
    """``robot_file_bytes``: a small file whole; a larger one only up to MAX_FILE_BYTES + 1 bytes (what
    makes ``load_robot`` refuse it), whatever its size."""
    small = tmp_path / "small.toml"
    small.write_bytes(b"x" * (READ_CHUNK + 7))
    assert robot_file_bytes(small) == b"x" * (READ_CHUNK + 7)
    big = tmp_path / "big.toml"
    big.write_bytes(b"y" * (MAX_FILE_BYTES + 10))
    assert robot_file_bytes(big) == b"y" * (MAX_FILE_BYTES + 1)
    with pytest.raises(RobotFileError, match="larger than"):
        load_robot(big)


def test_a_pose_may_name_its_variables_in_any_order():
    """``x=...,y=...`` (any order, as in a box) gives the pose the values alone give; a missing, repeated,
    unknown or unnamed variable among named ones is refused naming it; 0deg is exactly 0."""
    mel = load_robot(Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed000-mel-tsukuba.toml")
    plain, texts = parse_pose("1.5,-2,520,85deg,10deg,0deg", mel)
    named, named_texts = parse_pose("phi=0deg, theta=10deg,psi=85deg,z=520,y=-2,x=1.5", mel)
    assert np.array_equal(plain.lo, named.lo) and np.array_equal(plain.hi, named.hi) and texts == named_texts
    assert plain.lo[5] == plain.hi[5] == 0.0
    for text, word in (("x=1,y=2,z=3,psi=0,theta=0", "phi"), ("x=1,x=1,y=2,z=3,psi=0,theta=0,phi=0", "x"),
                       ("x=1,y=2,z=3,psi=0,theta=0,phi=0,w=1", "w"), ("x=1,2,3,0,0,0", "2")):
        with pytest.raises(InputError, match=word):
            parse_pose(text, mel)
    box, _ = parse_box("x=0:1,y=0:1,z=520:520,psi=0deg:1deg,theta=0:0,phi=0:0", mel)
    assert box.lo[3] == 0.0


PI_36 = "3.14159265358979323846264338327950288"      # pi = 3.14159265358979323846264338327950288419...


@pytest.mark.parametrize("phi, reversed_", [("45deg:0.7853981633974483", True), ("0.7853981633974483:45deg", False),
                                            (f"{PI_36}9:180deg", True), (f"{PI_36}:180deg", False),
                                            ("180deg:" + PI_36, True), ("1e-300:0deg", True), ("0deg:0", False)])
def test_a_range_with_an_end_in_degrees_is_compared_exactly(phi, reversed_):
    """pi/4 = 0.78539816339744830961... > 0.7853981633974483: a range from 45deg to that float is reversed
    (it was accepted, its float enclosures overlapping)."""
    mel = load_robot(Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed000-mel-tsukuba.toml")
    box = f"x=0:1,y=0:1,z=520,psi=0,theta=0,phi={phi}"
    if reversed_:
        with pytest.raises(InputError, match="exceeds"):
            parse_box(box, mel)
    else:
        parse_box(box, mel)


@pytest.mark.parametrize("name", ["two\nlines", "escape \x1b[2J", "bidi \u202e", "x" * 201])
def test_a_robot_name_that_could_forge_output_is_refused(name):
    """Every answer prints the robot's name: one line of printable characters, at most 200."""
    data = {"name": name, "kind": "planar-3rpr", "base": [["0", "0"], ["10", "0"], ["3", "10"]],
            "platform": [["0", "0"], ["4", "0"], ["2", "2"]]}
    with pytest.raises(RobotFileError, match="printable"):
        robot_from_dict(data)
    assert robot_from_dict({**data, "name": "Pétri 3-RPR (β = 2°)"}).name == "Pétri 3-RPR (β = 2°)"
    for empty in ("", "   "):                  # every answer started with ": "
        with pytest.raises(RobotFileError, match="name: empty"):
            robot_from_dict({**data, "name": empty})


def test_leg_length_arrays_of_the_wrong_shape_are_refused_saying_what_was_given():
    """An empty batch and an array of more than two dimensions are refused with what was wrong."""
    planar = robot_from_dict({"kind": "planar-3rpr", "base": [["0", "0"], ["10", "0"], ["3", "10"]],
                              "platform": [["0", "0"], ["4", "0"], ["2", "2"]]})
    for lengths, words in ((np.ones((0, 3)), "no set of leg lengths"), (np.ones((2, 2, 3)), "shape (2, 2, 3)"),
                           ([1, 2], "expected 3 leg lengths per instance")):
        with pytest.raises(InputError, match=re.escape(words)):
            parse_lengths(planar, lengths)
    rows, texts, batch = parse_lengths(planar, np.ones((2, 3)))
    assert batch and len(texts) == 2


def test_unknown_angles_are_an_input_error_naming_angles():
    """``with_angles("xyz")`` raised a plain ValueError (and ``with_angles(["zyz"])`` a TypeError,
    'unhashable type'): both are InputErrors naming ``angles``, with the same message."""
    robot = load_robot(EXAMPLES / "seed003-spherical-example-1.toml")
    with pytest.raises(InputError, match=r"^angles: unknown angles 'xyz' \(zyz or tilt-torsion\)$"):
        robot.with_angles("xyz")
    with pytest.raises(InputError, match=r"^angles: unknown angles \['zyz'\] \(zyz or tilt-torsion\)$"):
        robot.with_angles(["zyz"])
    assert robot.with_angles("tilt-torsion").with_angles("zyz").pose_names == ("phi1", "phi2", "phi3")


def _seed002_moved(scale, shift):
    """Seed 002's 6-6 robot with every coordinate times ``scale`` and its base moved by ``shift`` in x."""
    data = tomllib.loads((EXAMPLES / "seed002-general-6-6-24-solutions.toml").read_text())
    move = lambda p, dx: [str(Decimal(repr(c)) * Decimal(scale) + (Decimal(dx) if i == 0 else 0)) for i, c in enumerate(p)]  # noqa: E731
    return {"name": "moved", "kind": "gough-stewart", "base": [move(p, shift) for p in data["base"]],
            "platform": [move(p, 0) for p in data["platform"]]}


@pytest.mark.parametrize("scale, shift", [("1e-3", "0"), ("1e-6", "0"), ("1", "1000"), ("1", "1e9"), ("1e6", "0")])
def test_a_small_or_far_general_robot_is_not_called_degenerate(scale, shift):
    """The generic det(A) check depends on the shape only, not on the unit or the origin."""
    robot = robot_from_dict(_seed002_moved(scale, shift))
    assert robot.n_legs == 6


@pytest.mark.parametrize("scale", ["1", "1e-4"])
def test_collinear_base_joints_are_degenerate_at_any_scale(scale):
    data = _seed002_moved(scale, "0")
    data["base"] = [[str(k), "0", "0"] for k in (0, 1, 2, 3, 5, 8)]
    with pytest.raises(RobotFileError, match="Hadamard bound"):
        robot_from_dict(data)

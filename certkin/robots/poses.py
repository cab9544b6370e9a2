"""Numbers, poses, boxes, leg lengths and orientations from user values, enclosed exactly.

``parse_pose("-69,-50,500,85deg,10deg,0", robot)``, ``parse_box("x=-20:20,y=-20:20,
phi=0:0.7853981634", robot)``, ``parse_lengths(robot, "7.0710678,5.0990195,5")``,
``parse_orientation(robot, "0,5deg,0")``.  Values are exact decimals (an angle may carry
``deg``); each becomes the outward float enclosure of its exact value, so a certified box always
contains the box the user wrote.  A bound may be given once (``phi=0.5``) to fix a coordinate.

Errors raise ``InputError`` naming the *parameter* of the API function that took the value
(``lengths``, ``box``, ``start``, ...) and the field; the command line renames parameters to its
options (``certkin.cli``).  Robot files use ``parse_number`` with the file name as the source.

A numpy masked array (``numpy.ma``) of lengths or poses is taken only when nothing in it is
masked (it is then its data); one with a masked entry is refused (``unmasked``): a masked entry
has no value a certificate could be about, and reading its hidden data would answer another
question.
"""
from __future__ import annotations

from decimal import Decimal, InvalidOperation, localcontext
from fractions import Fraction
import math

import numpy as np

from intervals import Interval
from intervals.elementary import pi as PI
from intervals.rounding import enclose, enclose_plain

from ..errors import InputError, RobotFileError, clip, shown

RADIANS_PER_DEGREE = PI / Interval(180)   # an enclosure of π/180 (outward division)
MAX_MAGNITUDE = 1e12                       # |value| above this is far outside any robot: refused
MAX_ANGLE = 1e6                            # |angle| in radians above this is refused: the checker's sine and
                                           # cosine reduce arguments below 2^22 pi/2 only (proofs/arith.py)
MAX_EXPONENT = 400                         # a decimal's written exponent at most (the checker's ``MAX_EXPONENT``)
MAX_DIGITS = 1000                          # digits of a decimal at most: a certificate's checker reads texts of
                                           # 1100 characters (proofs/numbers.py), Python's int() 4300 digits


# ----------------------------------------------------------------- numbers
def exact_text(value) -> str:
    """The exact decimal text of a file value (Decimal, int or str)."""
    if isinstance(value, Decimal):
        return str(value)
    return str(value)


def parse_number(value, source: str, field: str, angle: bool = False) -> tuple[Interval, str]:
    """Enclose a number from a robot file or a user value.

    Accepts ints, exact decimals, decimal strings and, when ``angle`` is set,
    strings with a ``deg`` suffix (``"85deg"``, converted with a rigorous π).
    Returns the enclosure and the exact text.  Raises ``RobotFileError``, also for a magnitude
    above ``MAX_MAGNITUDE`` (1e12: millimetres that large describe no robot, and their squares
    and products would lose every digit or overflow), an angle above ``MAX_ANGLE`` radians, or a
    decimal of more than ``MAX_DIGITS`` digits (its certificate could not be checked).
    """
    iv, text = _parse_number(value, source, field, angle)
    if not angle and not (abs(float(iv.lo)) <= MAX_MAGNITUDE and abs(float(iv.hi)) <= MAX_MAGNITUDE):
        raise RobotFileError(source, field, f"{clip(text)} is out of range (at most {MAX_MAGNITUDE:g} in magnitude)")
    if angle and not (abs(float(iv.lo)) <= MAX_ANGLE and abs(float(iv.hi)) <= MAX_ANGLE):     # (the smaller limit)
        raise RobotFileError(source, field, f"{clip(text)} is out of range for an angle (at most {MAX_ANGLE:g} rad in "
                                            "magnitude, where a certificate can still be checked)")
    return iv, text


def unmasked(value, parameter: str, field: str = ""):
    """``value`` itself, or a numpy masked array's data when none of its entries is masked.

    A masked array with a masked entry raises ``InputError`` naming ``parameter`` (and the
    index of the first masked entry); its hidden data is never read as a value."""
    if not isinstance(value, np.ma.MaskedArray):
        return value
    mask = np.ma.getmaskarray(value)
    if mask.any():
        first = tuple(int(i) for i in np.argwhere(mask)[0])
        at = f" (the first at index {first[0] if len(first) == 1 else list(first)})" if first else ""
        raise InputError(parameter, field, f"a masked array with {int(mask.sum())} masked "
                                           f"entr{'y' if mask.sum() == 1 else 'ies'}{at}: every value must be given "
                                           "(a masked entry has no value to certify)")
    return np.ma.getdata(value)


def _parse_number(value, source: str, field: str, angle: bool) -> tuple[Interval, str]:
    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):    # (numpy.ma.masked, an entry of one)
        raise RobotFileError(source, field, "a masked entry: every value must be given (a masked entry has no value "
                                            "to certify)")
    if isinstance(value, np.generic) and not isinstance(value, (np.str_, np.bytes_)):
        value = value.item()                 # a numpy scalar: the Python number of the same value
    if isinstance(value, np.floating):       # a long double (``item`` keeps it): its shortest text, as a
        value = str(value)                   # float stands for its repr (float64 would round it, inward)
    if isinstance(value, Fraction):
        value = _fraction_text(value, source, field)
    if isinstance(value, bool) or value is None:
        got = "nothing" if value is None else str(value).lower()
        raise RobotFileError(source, field, f"expected a number, got {got}")
    text = value.strip() if isinstance(value, str) else value
    if isinstance(text, str) and (not text.isascii() or "_" in text):   # Decimal reads '5_5' as 55, '５' as 5
        raise RobotFileError(source, field, f"not a plain decimal number: {shown(value)} (digits 0-9, '.', 'e', "
                                            "a sign; no '_' or other scripts' digits)")
    if isinstance(text, (str, Decimal)) and too_many_digits(text):
        raise RobotFileError(source, field, f"a decimal of more than {MAX_DIGITS} digits (no robot needs that many, "
                                            "and a certificate's checker reads no more)")
    if isinstance(text, str) and text.lower().endswith("deg"):
        if not angle:
            raise RobotFileError(source, field, f"'deg' is only allowed for angles, got {shown(value)}")
        try:
            lo, hi = enclose(text[:-3].strip())
        except (ValueError, TypeError):
            raise RobotFileError(source, field, f"not a number of degrees: {shown(value)}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise RobotFileError(source, field, f"not a number of degrees: {shown(value)}")
        if lo == hi == 0.0:                      # 0deg is 0 exactly (a product would round it outward)
            return Interval(0.0), text
        return Interval.from_bounds(np.array(lo), np.array(hi)) * RADIANS_PER_DEGREE, text
    if isinstance(text, float):
        # tomllib with parse_float=Decimal never gives floats; Python callers may: the float stands for
        # its shortest repr, the decimal the caller wrote, enclosed outward (which holds the float too)
        if not math.isfinite(text):
            raise RobotFileError(source, field, f"not a finite number: {shown(text)}")
        text = repr(text)
    limit = f"at most {MAX_ANGLE:g} rad in magnitude" if angle else f"at most {MAX_MAGNITUDE:g} in magnitude"
    if isinstance(text, int) and abs(text) > MAX_MAGNITUDE:     # (before any text of its 5000 digits)
        raise RobotFileError(source, field, f"out of range ({limit})")
    if _below_any_float(text):
        raise RobotFileError(source, field, f"{_plain(value)} is below 1e-400 in magnitude: write 0")
    if _written_exponent_beyond(text):
        raise RobotFileError(source, field, f"{_plain(value)}: an exponent beyond ±{MAX_EXPONENT} (a certificate's "
                                            "checker reads no more): move the decimal point")
    try:
        lo, hi = enclose(text)
    except (ValueError, TypeError):
        raise RobotFileError(source, field, _not_a_number(value, text)) from None
    if not (math.isfinite(lo) and math.isfinite(hi)):       # a finite decimal beyond the float range
        raise RobotFileError(source, field, f"{_plain(value)} is out of range ({limit})")
    return Interval.from_bounds(np.array(lo), np.array(hi)), exact_text(text)


def _fraction_text(q: Fraction, source: str, field: str):
    """A fraction as the exact decimal it is (``Fraction(2899, 100)``: ``"28.99"``; an int when whole),
    since a claim states its numbers as exact decimals; one with no decimal (1/3) raises ``RobotFileError``."""
    den = q.denominator
    if den == 1:
        return q.numerator
    twos = (den & -den).bit_length() - 1
    fives, rest = 0, den >> twos
    while rest % 5 == 0 and fives <= 4 * MAX_DIGITS:
        fives, rest = fives + 1, rest // 5
    if rest != 1:
        raise RobotFileError(source, field, f"not an exact decimal: {shown(q)} (give a decimal number)")
    k = max(twos, fives)
    if k > 4 * MAX_DIGITS:
        raise RobotFileError(source, field, f"a decimal of more than {MAX_DIGITS} digits (no robot needs that "
                                            "many, and a certificate's checker reads no more)")
    return str(Decimal(f"{q.numerator * (10 ** k // den)}E-{k}"))


def too_many_digits(text) -> bool:
    """Whether a decimal (its text, or a ``Decimal``) has more than ``MAX_DIGITS`` digits, exponent included."""
    text = str(text)
    return len(text) > MAX_DIGITS and sum(c.isdigit() for c in text) > MAX_DIGITS


def _written_exponent_beyond(text) -> bool:
    """Whether a decimal text is written with an exponent beyond ±``MAX_EXPONENT`` (``2899e-405``: a value
    in range, but a text the checker refuses, ``proofs.numbers``)."""
    mantissa, e, exponent = str(text).lower().partition("e") if isinstance(text, str) else ("", "", "")
    if not (e and exponent.lstrip("+-").isdigit() and (len(exponent) > 6 or abs(int(exponent)) > MAX_EXPONENT)):
        return False
    try:                              # a value itself beyond the range is named as such, later
        return abs(Decimal(text).adjusted()) <= MAX_EXPONENT
    except (InvalidOperation, ValueError):
        return False


def _below_any_float(text) -> bool:
    """A nonzero decimal below 1e-400 in magnitude (no float tells it from 0; its exact value would be
    a fraction of that many digits, which the checker refuses and ``Fraction`` takes ages to build)."""
    try:
        d = text if isinstance(text, Decimal) else Decimal(text.strip()) if isinstance(text, str) else None
    except (InvalidOperation, ValueError):
        return False
    return d is not None and d.is_finite() and d != 0 and d.adjusted() < -400


def _plain(value) -> str:
    """A number in a message: a text as it was written, a decimal as its text (``shown``, unquoted)."""
    return clip(str(value).strip()) if isinstance(value, str) else shown(value)


def _not_a_number(value, text) -> str:
    """Why ``enclose`` refused a value: not finite (``nan``, ``inf``), or not a plain decimal (``0x10``, ``1/3``)."""
    try:
        finite = Decimal(text.strip() if isinstance(text, str) else text).is_finite()
    except (InvalidOperation, ValueError, TypeError, OverflowError):     # (Decimal([10**400] * 3): a tuple)
        finite = None
    if finite is False:
        return f"not a finite number: {shown(value)}"
    if isinstance(value, (str, Decimal)):
        return f"not a plain decimal number: {shown(value)} (digits 0-9, '.', 'e', a sign)"
    return f"expected a number, got {shown(value)}"


def _value(text, robot, name, parameter):
    try:
        return parse_number(text, parameter, name, angle=name in robot.angle_names)
    except InputError as exc:
        raise InputError(parameter, name, exc.problem) from None


def _exact(text):
    try:
        return Fraction(str(text))
    except (ValueError, ZeroDivisionError):
        return None


def exact_value(text) -> tuple[Fraction, bool]:
    """(exact rational, in degrees?) of a decimal text, ``deg`` allowed; ``ValueError`` if it is not one."""
    t = str(text).strip()
    return (Fraction(t[:-3]), True) if t.lower().endswith("deg") else (Fraction(t), False)


def exceeds(a, b) -> bool:
    """Whether the exact value of the text ``a`` exceeds that of ``b`` (``deg``: q·π/180).  A decimal
    and an angle in degrees differ unless both are 0 (π is irrational): mpmath at more digits than the
    two texts hold tells them apart."""
    try:
        (qa, da), (qb, db) = exact_value(a), exact_value(b)
    except (ValueError, ZeroDivisionError):
        return False
    if da == db:
        return qa > qb
    if qa == 0 or qb == 0:
        return qa > 0 if qb == 0 else qb < 0
    import mpmath                              # (rarely needed: not imported with the package)
    with mpmath.workdps(40 + len(str(a)) + len(str(b))):
        value = lambda q, d: mpmath.mpf(q.numerator) / q.denominator * (mpmath.pi / 180 if d else 1)  # noqa: E731
        return bool(value(qa, da) > value(qb, db))


# ----------------------------------------------------------------- poses and boxes
def parse_pose(text, robot, parameter="pose") -> tuple[Interval, list[str]]:
    """(d,) enclosure of a pose and its exact texts.  ``text``: the values in the order of the pose
    variables (``"0,0,520,85deg,10deg,0"``), or each named (``"x=0,y=0,z=520,..."``, any order, as
    in a box), a sequence of values, or a mapping {name: value}; a masked array only with nothing
    masked (``unmasked``)."""
    text = unmasked(text, parameter)
    if not isinstance(text, (str, list, tuple, dict, np.ndarray)):
        raise InputError(parameter, "", f"expected a pose (a text, a sequence of values or a mapping), got "
                                        f"{'nothing' if text is None else type(text).__name__}")
    if isinstance(text, np.ndarray) and text.ndim != 1:
        raise InputError(parameter, "", f"expected a pose (one value per pose variable), got an array of shape "
                                        f"{text.shape}")
    names = robot.pose_names
    if isinstance(text, dict):
        parts = _named_values(text.items(), names, parameter)
    else:
        parts = [p.strip() for p in text.split(",")] if isinstance(text, str) else list(text)
    if isinstance(text, str) and any("=" in p for p in parts):
        parts = _named(parts, names, parameter)
    if len(parts) != len(names):
        raise InputError(parameter, "", f"expected {len(names)} comma-separated values ({','.join(names)}), "
                                        f"got {len(parts)}")
    ivs, texts = [], []
    for name, p in zip(names, parts):
        iv, t = _value(p, robot, name, parameter)
        ivs.append(iv)
        texts.append(str(t))
    return Interval.from_bounds(np.array([float(i.lo) for i in ivs]), np.array([float(i.hi) for i in ivs])), texts


def _named(parts, names, parameter) -> list[str]:
    """The values of a pose given as ``name=value`` parts, in the order of ``names``."""
    pairs = []
    for part in parts:
        if "=" not in part:
            raise InputError(parameter, part, f"expected name=value for every variable ({','.join(names)}) "
                                              "or values alone")
        pairs.append(tuple(t.strip() for t in part.split("=", 1)))
    return _named_values(pairs, names, parameter)


def _named_values(pairs, names, parameter) -> list:
    """The values of (name, value) pairs in the order of ``names``: each variable once, none missing."""
    given = {}
    for name, value in pairs:
        if name not in names:
            raise InputError(parameter, name, f"not a pose variable of this robot ({','.join(names)})")
        if name in given:
            raise InputError(parameter, name, "given twice")
        given[name] = value
    missing = [n for n in names if n not in given]
    if missing:
        raise InputError(parameter, ",".join(missing), "missing")
    return [given[n] for n in names]


def parse_box(spec, robot, parameter="box") -> tuple[Interval, dict]:
    """(d,) box enclosing the user's box, and the exact texts {name: [lo, hi]}.

    ``spec`` is a string ``"x=a:b,y=c:d,..."`` or a dict ``{name: (a, b)}``.
    Every pose variable of the robot must be given.
    """
    if isinstance(spec, str):
        items = {}
        for part in [p.strip() for p in spec.split(",") if p.strip()]:
            if "=" not in part:
                raise InputError(parameter, part, "expected name=lo:hi")
            name, rng = (s.strip() for s in part.split("=", 1))
            if name in items:
                raise InputError(parameter, name, "given twice")
            bounds = rng.split(":")
            if len(bounds) == 1:
                bounds = [bounds[0], bounds[0]]
            if len(bounds) != 2 or not all(b.strip() for b in bounds):
                raise InputError(parameter, name, f"expected lo:hi, got {shown(rng)}")
            items[name] = (bounds[0].strip(), bounds[1].strip())
    elif isinstance(spec, dict):
        items = {}
        for k, v in spec.items():
            if isinstance(v, (list, tuple)) and len(v) == 2:
                items[k] = (v[0], v[1])
            else:
                items[k] = (v, v)
    else:
        raise InputError(parameter, "", "expected 'name=lo:hi,...' or a mapping")
    for name in items:
        if name not in robot.pose_names:
            raise InputError(parameter, name, f"{robot.kind} robots have no variable {shown(name)} "
                                              f"(their pose is {','.join(robot.pose_names)})")
    missing = [n for n in robot.pose_names if n not in items]
    if missing:
        raise InputError(parameter, missing[0], "missing (every pose variable needs a range or a value)")
    lo, hi, texts = [], [], {}
    for name in robot.pose_names:
        a, b = items[name]
        ia, ta = _value(a, robot, name, parameter)
        ib, tb = _value(b, robot, name, parameter)
        if float(ia.lo) > float(ib.hi) or exceeds(ta, tb):
            raise InputError(parameter, name, f"lower bound {clip(str(ta))} exceeds upper bound {clip(str(tb))}")
        lo.append(float(ia.lo))
        hi.append(float(ib.hi))
        texts[name] = [str(ta), str(tb)]
    return Interval.from_bounds(np.array(lo), np.array(hi)), texts


def inner_box(texts: dict, robot):
    """Float bounds inside the exact box ``texts`` ({name: [lo, hi]}): per variable, the least float at or
    above lo and the greatest at or below hi, so a witness there lies in the box the user asked about.
    Where no float lies inside (a fixed irrational value such as 45deg), the enclosure of lo and
    ``exact`` True: a witness takes that exact value, enclosed.  Returns (lo, hi, exact) arrays."""
    lo, hi, exact = [], [], []
    for name in robot.pose_names:
        a, _ = _value(texts[name][0], robot, name, "box")
        b, _ = _value(texts[name][1], robot, name, "box")
        inside = float(a.hi) <= float(b.lo)
        lo.append(float(a.hi) if inside else float(a.lo))
        hi.append(float(b.lo) if inside else float(a.hi))
        exact.append(not inside)
    return np.array(lo), np.array(hi), np.array(exact)


# ----------------------------------------------------------------- leg lengths
def parse_lengths(robot, lengths, parameter="lengths"):
    """(rows of enclosures, rows of exact texts, whether the input was a batch) of one set of leg
    lengths (sequence or "l1,l2,..." text) or a 2-D array with one row per instance (or a list of
    "l1,l2,..." texts, one per instance); a masked array only with nothing masked (``unmasked``)."""
    lengths = unmasked(lengths, parameter)
    if isinstance(lengths, str):
        lengths = [p.strip() for p in lengths.split(",")]
    elif isinstance(lengths, (list, tuple)) and lengths and all(isinstance(r, str) and "," in r for r in lengths):
        lengths = [[p.strip() for p in r.split(",")] for r in lengths]
    arr = np.asarray(lengths, dtype=object)
    batch = arr.ndim == 2
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim == 2 and arr.shape[0] == 0:
        raise InputError(parameter, "", "no set of leg lengths (an empty array)")
    if arr.ndim != 2:
        raise InputError(parameter, "", f"expected {robot.n_legs} leg lengths, or one row of {robot.n_legs} per instance "
                                        f"(a 2-D array), got " + (f"a value of type {type(lengths).__name__}" if arr.ndim == 0
                                                                  else f"an array of shape {arr.shape}"))
    if arr.shape[1] != robot.n_legs:
        raise InputError(parameter, "", f"expected {robot.n_legs} leg lengths per instance")
    rows, texts = [], []
    for i, row in enumerate(arr):
        ivs, ts = [], []
        for j, v in enumerate(row):
            if isinstance(v, (float, np.floating)):
                v = repr(float(v))  # a float stands for its shortest repr, enclosed (as ``parse_number``)
            field_name = f"[{i}][{j}]" if batch else f"leg {j + 1}"
            iv, t = _length(v, parameter, field_name)
            ivs.append(iv)
            ts.append(str(t))
        rows.append(ivs)
        texts.append(ts)
    return rows, texts, batch


def _length(value, parameter, field_name):
    """(enclosure, exact text) of one leg length: a number, or a range ``"lo:hi"`` or ``"v+-t"``
    (also ``"v±t"``) of exact decimals, whose text is then ``"lo:hi"`` (``v ∓ t`` computed exactly)."""
    text = value.strip() if isinstance(value, str) else value
    if isinstance(text, str) and (":" in text or "+-" in text or "±" in text):
        if ":" in text:
            parts = text.split(":")
        else:
            centre, _, tol = text.replace("±", "+-").partition("+-")
            try:
                v, t = Decimal(centre.strip()), Decimal(tol.strip())
            except (InvalidOperation, ValueError):
                raise InputError(parameter, field_name, f"not a length range: {shown(value)}") from None
            if not (v.is_finite() and t.is_finite()) or t < 0:
                raise InputError(parameter, field_name, f"not a length range (tolerance >= 0): {shown(value)}")
            if max(abs(v), t) > MAX_MAGNITUDE:
                raise InputError(parameter, field_name, f"{clip(value.strip())} is out of range (at most "
                                                        f"{MAX_MAGNITUDE:g} in magnitude)")
            if any(d and d.adjusted() < -400 for d in (v, t)):
                raise InputError(parameter, field_name, f"{clip(value.strip())}: a term below 1e-400 (write 0 for an "
                                                        "exact length or value)")
            with localcontext() as ctx:     # exact: every digit of both operands, and a carry
                exponent = min(v.as_tuple().exponent, t.as_tuple().exponent)
                ctx.prec = max(v.adjusted(), t.adjusted(), 0) - min(exponent, 0) + 3
                parts = [format(v - t, "f"), format(v + t, "f")]
        if len(parts) != 2:
            raise InputError(parameter, field_name, f"expected 'lo:hi' or 'value+-tolerance', got {shown(value)}")
        (lo, lo_t), (hi, hi_t) = (_length(part, parameter, field_name) for part in parts)
        if Fraction(lo_t) > Fraction(hi_t):
            raise InputError(parameter, field_name, f"range {clip(f'{lo_t}:{hi_t}')} has lo > hi")
        return Interval.from_bounds(lo.lo, hi.hi), f"{lo_t}:{hi_t}"
    try:
        iv, t = parse_number(value, parameter, field_name)
    except InputError as exc:
        raise InputError(parameter, exc.field, exc.problem) from None
    if float(iv.lo) < 0:
        raise InputError(parameter, field_name, f"a leg length cannot be negative ({clip(str(t))})")
    return iv, t


def length_enclosures(robot, lengths):
    """(enclosures (M, legs), rows of exact texts, whether the input was a batch): ``parse_lengths``
    as arrays, with a direct path for one set of floats or plain decimal texts (a float stands for
    its text repr(v), as there; anything else, or any doubt, takes ``parse_lengths``)."""
    lengths = unmasked(lengths, "lengths")
    items = lengths.split(",") if isinstance(lengths, str) else lengths
    if isinstance(items, (list, tuple)) and len(items) == robot.n_legs:
        lo, hi, texts = [], [], []
        for v in items:
            if isinstance(v, float):
                t = repr(float(v))
            elif isinstance(v, str) and v.isascii() and "_" not in v and len(v) <= MAX_DIGITS:
                t = v.strip()
            else:
                break
            ab = enclose_plain(t)
            if ab is None or not (ab[0] >= 0 and ab[1] <= MAX_MAGNITUDE) or ab[0] == 0.0 < ab[1]:
                break                        # (a tiny nonzero length: parse_lengths says whether it is taken)
            a, b = ab
            lo.append(a)
            hi.append(b)
            texts.append(t)
        else:
            return Interval.from_bounds(np.array([lo]), np.array([hi])), [texts], False
    rows, texts, batch = parse_lengths(robot, lengths)
    return (Interval.from_bounds(np.array([[float(v.lo) for v in r] for r in rows]),
                                 np.array([[float(v.hi) for v in r] for r in rows])), texts, batch)


def float_length_rows(robot, lengths):
    """(enclosures (M, legs), texts) of a 2-D float array of leg lengths, or None for other input
    (``parse_lengths`` then parses it and reports bad values).

    As in ``length_enclosures``, a float's text is its ``repr``: the shortest decimal that rounds
    to it, so that decimal lies within half a spacing of the float, between the float's two
    neighbours — the enclosure used here (no decimal-to-rational conversion per value).  A masked
    array is None too (``parse_lengths`` refuses it if an entry is masked).
    """
    if not isinstance(lengths, np.ndarray) or isinstance(lengths, np.ma.MaskedArray) or lengths.dtype.kind != "f" or lengths.ndim != 2 \
            or lengths.shape[1] != robot.n_legs or not len(lengths):
        return None
    v = lengths.astype(np.float64)
    if not (np.all(np.isfinite(v)) and np.all(v >= 0) and np.all(v <= MAX_MAGNITUDE)):
        return None
    texts = [[repr(t) for t in row] for row in v.tolist()]
    lo = np.where(v > 0, np.nextafter(v, -np.inf), 0.0)
    return Interval.from_bounds(lo, np.nextafter(v, np.inf)), texts


# ----------------------------------------------------------------- orientations and heights
def decimal_text(value):
    """A float becomes its exact decimal expansion (never the decimal it was printed from); a 0-d array
    its value."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value):
            return repr(float(value))
        return str(Decimal(float(value)))
    return value


def _number(value, parameter, name, angle):
    try:
        return parse_number(decimal_text(value), parameter, name, angle=angle)
    except InputError as exc:
        raise InputError(parameter, name, exc.problem) from None


def orientation_names(robot) -> tuple[str, ...]:
    """The robot's pose angles, in pose order (Gough-Stewart psi, theta, phi; planar phi)."""
    return tuple(n for n in robot.pose_names if n in robot.angle_names)


def parse_orientation(robot, orientation, parameter="orientation"):
    """([Interval] per angle, [exact text]) from ``"psi,theta,phi"`` (``deg`` allowed), a sequence or a mapping.

    ``None`` means every angle 0.  Planar robots take one angle, ``phi``.  A masked array only
    with nothing masked (``unmasked``).
    """
    orientation = unmasked(orientation, parameter)
    names = orientation_names(robot)
    if orientation is None:
        parts = ["0"] * len(names)
    elif isinstance(orientation, str):
        parts = [p.strip() for p in orientation.split(",")]
    elif isinstance(orientation, dict):
        unknown = [k for k in orientation if k not in names]
        if unknown:
            raise InputError(parameter, str(unknown[0]), f"unknown angle (the angles are {','.join(names)})")
        parts = [orientation.get(n, "0") for n in names]
    else:
        try:
            parts = list(orientation)
        except TypeError:
            parts = [orientation]
    if len(parts) != len(names):
        raise InputError(parameter, "", f"expected {len(names)} comma-separated angles ({','.join(names)}), "
                                        f"got {len(parts)}")
    ivs, texts = [], []
    for name, p in zip(names, parts):
        if isinstance(p, str) and not p.strip():
            raise InputError(parameter, name, "missing value")
        iv, text = _number(p, parameter, name, True)
        ivs.append(iv)
        texts.append(str(text))
    return ivs, texts


def parse_height(value, parameter="z", name="z"):
    """(enclosure, exact text) of a height ``z``."""
    if value is None or (isinstance(value, str) and not value.strip()):
        raise InputError(parameter, name, "missing value")
    iv, text = _number(value.strip() if isinstance(value, str) else value, parameter, name, False)
    return iv, str(text)


def parse_height_range(value, parameter="z_range"):
    """((enclosure, text), (enclosure, text)) of ``"lo:hi"`` or a pair, lo < hi exactly."""
    value = unmasked(value, parameter, "z")
    if isinstance(value, str):
        parts = value.split(":")
        if len(parts) != 2:
            raise InputError(parameter, "z", f"expected lo:hi, got {shown(value)}")
    else:
        parts = list(value) if isinstance(value, (list, tuple)) or getattr(value, "ndim", 0) == 1 else []
        if len(parts) != 2:
            raise InputError(parameter, "z", "expected lo:hi or a pair (lo, hi)")
    (a, ta), (b, tb) = parse_height(parts[0], parameter, "z"), parse_height(parts[1], parameter, "z")
    if not Fraction(ta) < Fraction(tb):
        raise InputError(parameter, "z", f"lower bound {clip(ta)} must be below upper bound {clip(tb)}")
    return (a, ta), (b, tb)

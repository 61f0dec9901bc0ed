"""Readers of the files curvesfm writes. Every problem raises InputError with one line that names
the file (and line), so that the command line can print it as it is."""
import csv
import json
import math
import os


NUMBER = (int, float)
KIND_NAMES = {list: "a list", dict: "an object", str: "a string", NUMBER: "a number"}


class InputError(Exception):
    """A missing or malformed input file, or a missing dependency: one line for the user."""


class UsageError(InputError):
    """A bad argument (exit code 2, as curvesfm's usage errors)."""


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except OSError as e:
        raise InputError("%s: cannot read: %s" % (path, e.strerror))
    except ValueError as e:
        raise InputError("%s: not valid JSON: %s" % (path, e))


def field(document, path, key_path, kind=None):
    """document[k1][k2]... for key_path "k1.k2...", checked to be a `kind` when given."""
    value = document
    for key in key_path.split("."):
        if not isinstance(value, dict) or key not in value:
            raise InputError('%s: expected the key "%s"' % (path, key_path))
        value = value[key]
    if kind is not None and not isinstance(value, kind):
        raise InputError('%s: "%s" should be %s, found %s'
                         % (path, key_path, KIND_NAMES[kind], json.dumps(value)[:40]))
    return value


def numbers(document, path, key_path, width=None):
    """A list of numbers (width None) or of [x, y, z]-like rows of `width` numbers."""
    values = field(document, path, key_path, list)
    for i, v in enumerate(values):
        row = v if width is not None else [v]
        if (width is not None and (not isinstance(v, list) or len(v) != width)) or not all(
                isinstance(x, NUMBER) and not isinstance(x, bool) for x in row):
            expected = "a number" if width is None else "%d numbers" % width
            raise InputError('%s: "%s"[%d] should be %s, found %s'
                             % (path, key_path, i, expected, json.dumps(v)))
    return values


def _read_lines(path):
    try:
        with open(path) as f:
            return f.read().splitlines()
    except OSError as e:
        raise InputError("%s: cannot read: %s" % (path, e.strerror))


def read_obj(path):
    """Curves of a curvesfm curves.obj: [(name, [polyline, ...])], a polyline being a list of
    (x, y, z) from one `l` line of 1-based vertex indices, grouped by the `o` line before it."""
    vertices, curves = [], []
    for number, line in enumerate(_read_lines(path), 1):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        where = "%s:%d" % (path, number)
        if words[0] == "o":
            curves.append((" ".join(words[1:]) or "curve_%d" % len(curves), []))
        elif words[0] == "v":
            vertices.append(_vertex(words, where))
        elif words[0] == "l":
            if not curves:
                raise InputError("%s: expected an 'o' line before the first 'l' line" % where)
            curves[-1][1].append([vertices[i - 1] for i in _indices(words, len(vertices), where)])
        else:
            raise InputError("%s: expected an 'o', 'v' or 'l' line, found '%s'" % (where, words[0]))
    return curves


def _vertex(words, where):
    try:
        xyz = tuple(float(w) for w in words[1:])
    except ValueError:
        xyz = ()
    if len(xyz) != 3 or not all(math.isfinite(c) for c in xyz):
        raise InputError("%s: expected 'v x y z' with 3 finite numbers, found '%s'"
                         % (where, " ".join(words)))
    return xyz


def _indices(words, count, where):
    try:
        indices = [int(w) for w in words[1:]]
    except ValueError:
        raise InputError("%s: expected 'l' and vertex indices, found '%s'" % (where, " ".join(words)))
    bad = [i for i in indices if not 1 <= i <= count]
    if len(indices) < 2 or bad:
        raise InputError("%s: expected 2 or more vertex indices in [1, %d], found '%s'"
                         % (where, count, " ".join(words)))
    return indices


def read_tum(path):
    """A TUM trajectory: [(timestamp, (tx, ty, tz), (qx, qy, qz, qw))], camera-to-world."""
    poses = []
    for number, line in enumerate(_read_lines(path), 1):
        words = line.split()
        if not words or words[0].startswith("#"):
            continue
        try:
            values = [float(w) for w in words]
        except ValueError:
            values = []
        if len(values) != 8:
            raise InputError('%s:%d: expected 8 numbers "timestamp tx ty tz qx qy qz qw", found '
                             "'%s'" % (path, number, line.strip()))
        poses.append((values[0], tuple(values[1:4]), tuple(values[4:8])))
    return poses


def read_csv(path, columns):
    """Rows of a CSV file as dicts; the header must hold every name in `columns`."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in columns if c not in (reader.fieldnames or [])]
            if missing:
                raise InputError("%s:1: expected the columns %s, missing %s"
                                 % (path, ", ".join(columns), ", ".join(missing)))
            return list(reader)
    except OSError as e:
        raise InputError("%s: cannot read: %s" % (path, e.strerror))


def number(row, column, path):
    """row[column] as a float ('nan' and '' give NaN, as the benches write for failed cases)."""
    text = row[column]
    try:
        return float(text) if text != "" else math.nan
    except ValueError:
        raise InputError("%s: column %s: expected a number, found '%s'" % (path, column, text))


def require_extension(path, extensions, what):
    extension = os.path.splitext(path)[1].lower()
    if extension not in extensions:
        raise UsageError("%s '%s': expected a file name ending in %s"
                         % (what, path, " or ".join(extensions)))
    return extension[1:]

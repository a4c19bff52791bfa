"""A MotionBenchMaker problem set as the benchmark scripts read it: a folder of family folders
(sceneNNNN.yaml + requestNNNN.yaml), or a .tar.bz2 of one (unpacked to a temporary folder)."""

import tarfile
import tempfile
from pathlib import Path


def unpacked(path):
    """The set's root folder (a .tar.bz2 is unpacked into a temporary folder kept alive with
    the returned object's `keep` attribute)."""
    path = Path(path)
    if path.suffix != ".bz2":
        return path
    tmp = tempfile.TemporaryDirectory()
    with tarfile.open(path) as t:
        t.extractall(tmp.name, filter="data")
    root = Path(tmp.name)
    inner = [p for p in root.iterdir() if p.is_dir()]
    if len(inner) == 1 and not any(inner[0].glob("request*.yaml")):
        root = inner[0]
    unpacked.keep.append(tmp)
    return root


unpacked.keep = []


def problems(root):
    """(family, number, scene, request) of every problem, families and numbers in order."""
    for family in sorted(p for p in Path(root).iterdir() if p.is_dir()):
        for request in sorted(family.glob("request*.yaml")):
            number = request.stem[len("request"):]
            scene = family / f"scene{number}.yaml"
            if scene.is_file():
                yield family.name, int(number), scene, request


def by_family(rows):
    """(family, its rows, the valid ones, the solved ones) for each family in order, then for
    `all` (rows are dicts with `family`, `valid` and `solved`)."""
    for family in sorted({r["family"] for r in rows}) + ["all"]:
        sel = [r for r in rows if family in ("all", r["family"])]
        valid = [r for r in sel if r["valid"]]
        yield family, sel, valid, [r for r in valid if r["solved"]]

#!/usr/bin/env python3
"""Independent oracle for the molecule readers (ASE 3.29, `pip install ase`).

Reads every sample file in <workspace>/../shared/data with ASE and writes
crates/molecule/tests/oracle/expected.json: atom count, frame count, element counts and the
positions (Å) of the first and last atom of the first and last frame. The Rust test
`tests/samples.rs` compares against it to 1e-4 Å.

Notes on ASE conventions we undo here:
- LAMMPS dumps without an `element` column: ASE sets Z = type; we record type counts under
  "type_counts" instead of element counts (our reader gives Z = 0 / uses --types).
- LAMMPS dumps with scaled coordinates: ASE drops the box origin (celldisp); we add it back.
- LAMMPS data: ASE maps masses to elements only when asked; we give it Z_of_type from masses.
Run:  python3 crates/molecule/tests/oracle/make_expected.py
"""
import collections
import gzip
import json
import os
import sys

import ase.io
from ase.data import atomic_masses, chemical_symbols

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.normpath(os.path.join(HERE, "..", "..", "..", "..", "..", "shared", "data"))


def pos(a, i):
    return [float(v) for v in a.positions[i]]


def describe(frames, extra=None):
    first, last = frames[0], frames[-1]
    d = {
        "atoms": len(first),
        "frames": len(frames),
        "element_counts": dict(sorted(collections.Counter(first.get_chemical_symbols()).items())),
        "first_frame_first_atom": pos(first, 0),
        "first_frame_last_atom": pos(first, len(first) - 1),
        "last_frame_first_atom": pos(last, 0),
        "last_frame_last_atom": pos(last, len(last) - 1),
    }
    if extra:
        d.update(extra)
    return d


def name_rule_counts(names):
    """Element from an atom name: ion names NA/CL -> Na/Cl, MW (TIP4P dummy) -> X, otherwise
    the first letter (all atoms in these biomolecular files are H, C, N, O, S)."""
    c = collections.Counter()
    for n in names:
        n = n.strip()
        if n in ("NA", "CL"):
            c[n.capitalize()] += 1
        elif n == "MW":
            c["X"] += 1
        else:
            c[n.lstrip("0123456789")[0]] += 1
    return dict(sorted(c.items()))


def dump_header_columns(path):
    op = gzip.open if path.endswith(".gz") else open
    with op(path, "rt") as f:
        for line in f:
            if line.startswith("ITEM: ATOMS"):
                return line.split()[2:]
    return []


def main():
    if not os.path.isdir(DATA):
        sys.exit(f"data dir not found: {DATA}")
    out = {}
    # XYZ
    fr = ase.io.read(os.path.join(DATA, "2r9r-1b.xyz"), index=":", format="extxyz")
    out["2r9r-1b.xyz"] = describe(fr)
    # PDB. ASE guesses elements from the first two letters of the atom name (CA -> Ca, HG1 -> Hg),
    # which is wrong for proteins; element counts use the PDB naming rule instead (see below).
    p = os.path.join(DATA, "adk_open.pdb")
    fr = ase.io.read(p, index=":", format="proteindatabank")
    names = [l[12:16] for l in open(p) if l.startswith(("ATOM", "HETATM"))]
    out["adk_open.pdb"] = describe(fr, {"element_counts": name_rule_counts(names)})
    # GRO (same remark about ASE's element guess; TIP4P "MW" is a massless site -> unknown)
    p = os.path.join(DATA, "adk_oplsaa.gro")
    fr = ase.io.read(p, index=":", format="gromacs")
    lines = open(p).read().splitlines()[2:-1]
    names = [l[10:15] for l in lines]
    out["adk_oplsaa.gro"] = describe(fr, {"element_counts": name_rule_counts(names)})
    # LAMMPS data: masses -> elements (nearest standard weight)
    p = os.path.join(DATA, "cnt-hexagonal-class1.data")
    a = ase.io.read(p, format="lammps-data", units="real", atom_style="full", sort_by_id=True)
    types = a.arrays["type"]
    masses = a.get_masses()
    z_of_type = {}
    for t, m in zip(types, masses):
        z_of_type[int(t)] = int(min(range(1, 104), key=lambda z: abs(atomic_masses[z] - m)))
    a = ase.io.read(p, format="lammps-data", units="real", atom_style="full", sort_by_id=True, Z_of_type=z_of_type)
    nb = 0
    with open(p) as f:
        for line in f:
            if line.strip().endswith(" bonds") and len(line.split()) == 2:
                nb = int(line.split()[0])
    out["cnt-hexagonal-class1.data"] = describe([a], {"file_bonds": nb})
    # LAMMPS dumps
    for name in ["mass_q_elem.lammpstrj", "albite_triclinic.dump", "spce_water.lammpstrj.gz"]:
        p = os.path.join(DATA, name)
        cols = dump_header_columns(p)
        op = gzip.open if name.endswith(".gz") else open
        with op(p, "rt") as f:
            fr = ase.io.read(f, index=":", format="lammps-dump-text")
        scaled = not any(c in cols for c in ("x", "xu"))
        if scaled:
            for at in fr:
                at.positions += at.get_celldisp().reshape(3)
        extra = {}
        d = describe(fr)
        if "element" not in cols:
            d["type_counts"] = {str(k): v for k, v in sorted(collections.Counter(int(n) for n in fr[0].numbers).items())}
            d["element_counts"] = {"X": len(fr[0])}
        d.update(extra)
        out[name] = d
    path = os.path.join(HERE, "expected.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1, sort_keys=True)
        f.write("\n")
    print("wrote", path)
    for k, v in out.items():
        print(k, v["atoms"], v["frames"], v["element_counts"])


if __name__ == "__main__":
    main()

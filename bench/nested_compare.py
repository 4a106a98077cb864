"""Two nested cross-validation runs (``bench/identify_cv.py --json``) on the records both kept out.

Prints, over the records in both files, the mean heading RMS [deg] of the scaled model and of each
run's identified model, and on how many records the first run's identified model is lower.  Used by
docs/benchmark_frt.md to set a training subset's run beside the run over all records.

    python bench/nested_compare.py A.json B.json
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def compare(a: dict, b: dict, key: str = "heading_rms_deg") -> dict:
    """{"records", "scaled", "a", "b", "a_lower"} over the records of ``a`` and ``b`` (nested-CV JSONs)."""
    ra = {r["name"]: r for r in a["records"]}
    rb = {r["name"]: r for r in b["records"]}
    common = [n for n in rb if n in ra]
    if not common:
        raise ValueError("the two runs kept out no record in common")
    x = [ra[n]["identified"][key] for n in common]
    y = [rb[n]["identified"][key] for n in common]
    mean = lambda v: sum(v) / len(v)  # noqa: E731
    return {"records": len(common), "scaled": mean([rb[n]["scaled"][key] for n in common]), "a": mean(x),
            "b": mean(y), "a_lower": sum(p < q for p, q in zip(x, y))}


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print("usage: python bench/nested_compare.py A.json B.json", file=sys.stderr)
        return 2
    a, b = (json.loads(Path(p).read_text()) for p in argv)
    c = compare(a, b)
    print(f"{c['records']} records kept out by both: mean heading RMS scaled {c['scaled']:.2f} deg, "
          f"{argv[0]} {c['a']:.2f} deg, {argv[1]} {c['b']:.2f} deg; the first lower on {c['a_lower']} of {c['records']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

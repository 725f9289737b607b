"""Fingerprints of whole runs: a hash of every table and every bag file of fixed cases.

A move or a refactoring must leave results bit for bit as they were. Run this before and
after, and compare the two files::

    python bench/fingerprint.py --out /tmp/before.json            # on the old code
    python bench/fingerprint.py --out /tmp/after.json --compare /tmp/before.json

Tables are hashed by content (column names, dtypes and every value, through pandas'
``hash_pandas_object``), so a parquet writer's metadata does not count; bags are hashed
byte for byte (``metadata.yaml`` and the ``.mcap`` / ``.db3`` files). The cases are the six
acceptance scenarios (the mixed-reality ones with their physical robot made virtual, as
real time and DDS are not deterministic) and variants that touch every pluggable choice of
the network, motion capture and mapping.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pandas as pd

VIRTUAL = ["--set", "physical.robots=[]", "--set", "mocap.source=simulated"]

CASES: dict[str, list[str]] = {
    "warehouse-random": ["warehouse-random", "--duration-s", "40"],
    "warehouse-rows": ["warehouse-rows", "--duration-s", "40"],
    "fleet50": ["fleet50", "--duration-s", "15"],
    "lab-real-in-virtual": ["lab-real-in-virtual", "--duration-s", "30", *VIRTUAL],
    "lab-mixed": ["lab-mixed", "--duration-s", "30", *VIRTUAL],
    "warehouse-humans": ["warehouse-humans", "--duration-s", "30"],
    "mapping-scans-degraded": [
        "warehouse-mapping",
        "--duration-s",
        "30",
        "--set",
        "mapping.share='scans'",
        "--set",
        "network.profile='wifi_degraded'",
    ],
    "mapping-maps-binomial": [
        "warehouse-mapping",
        "--duration-s",
        "30",
        "--set",
        "mapping.share='maps'",
        "--set",
        "network.topology='binomial'",
        "--set",
        "network.latency_model='lognormal'",
        "--set",
        "network.latency_ms=8.0",
        "--set",
        "network.jitter_ms=4.0",
    ],
    "cbba-ring-bernoulli": [
        "warehouse-random",
        "--duration-s",
        "30",
        "--set",
        "assignment.protocol='cbba'",
        "--set",
        "network.topology='ring'",
        "--set",
        "network.loss_model='bernoulli'",
        "--set",
        "network.loss_prob=0.1",
        "--set",
        "network.latency_model='normal'",
        "--set",
        "network.latency_ms=5.0",
        "--set",
        "network.jitter_ms=2.0",
        "--set",
        "mocap.source='simulated'",
    ],
    "hungarian-degraded": [
        "warehouse-rows",
        "--duration-s",
        "30",
        "--set",
        "assignment.protocol='hungarian'",
        "--set",
        "network.profile='wifi_degraded'",
    ],
    "greedy-range-pathloss": [
        "warehouse-rows",
        "--duration-s",
        "30",
        "--set",
        "assignment.protocol='greedy'",
        "--set",
        "network.topology='range'",
        "--set",
        "network.range_m=12.0",
        "--set",
        "network.path_loss=true",
        "--set",
        "network.bandwidth_mbps=1.0",
    ],
}


WALL_CLOCK = {"navigation.parquet": ["plan_ms"]}
"""Columns that measure the machine, not the simulation (left out of the hash)."""


def table_hash(path: Path) -> str:
    """The content of one parquet table: columns, dtypes, values (index ignored)."""
    frame = pd.read_parquet(path).drop(columns=WALL_CLOCK.get(path.name, []))
    digest = hashlib.sha256()
    digest.update(repr([(str(c), str(t)) for c, t in frame.dtypes.items()]).encode())
    if len(frame):
        digest.update(pd.util.hash_pandas_object(frame, index=False).to_numpy().tobytes())
    return digest.hexdigest()[:16]


def file_hash(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def run_case(cosim: str, name: str, args: list[str], root: Path) -> dict[str, str]:
    out = root / name
    command = [cosim, "run", *args, "--out", str(out), "--quiet", "--seed", "3"]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        return {"error": f"exit {done.returncode}: {done.stderr.strip()[-500:]}"}
    found: dict[str, str] = {}
    for table in sorted((out / "tables").glob("*.parquet")):
        found[f"tables/{table.name}"] = table_hash(table)
    for part in sorted((out / "bag").iterdir()):
        found[f"bag/{part.name}"] = file_hash(part)
    summary = json.loads((out / "summary.json").read_text())
    volatile = (
        "wall",
        "real_time",
        "version",
        "started",
        "compile",
        "host",
        "worker",
        "path",
        "thread",
    )
    kept = {k: v for k, v in summary.items() if not any(w in k for w in volatile)}
    for key, value in sorted(kept.items()):  # by key, so a difference names its entry
        found[f"summary/{key}"] = hashlib.sha256(json.dumps(value).encode()).hexdigest()[:16]
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="JSON file of the hashes")
    parser.add_argument("--cosim", default=str(Path(sys.executable).parent / "cosim"))
    parser.add_argument("--compare", type=Path, help="an earlier file: print what differs")
    parser.add_argument("--only", action="append", choices=sorted(CASES))
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    names = args.only or list(CASES)
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(args.jobs) as pool:
        futures = {n: pool.submit(run_case, args.cosim, n, CASES[n], Path(tmp)) for n in names}
        hashes = {n: f.result() for n, f in futures.items()}
    args.out.write_text(json.dumps(hashes, indent=1, sort_keys=True) + "\n")
    print(f"wrote {args.out}")
    if args.compare is None:
        return 0
    before = json.loads(args.compare.read_text())
    differ = 0
    for name in names:
        old, new = before.get(name, {}), hashes[name]
        for key in sorted(set(old) | set(new)):
            if old.get(key) != new.get(key):
                differ += 1
                print(f"DIFFERS {name} {key}: {old.get(key)} -> {new.get(key)}")
        if old == new:
            print(f"same    {name}: {len(new)} files")
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())

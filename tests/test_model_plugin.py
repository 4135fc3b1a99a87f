"""A contact model declared in one file outside the package (tests/data/edge_model.py: two tips
``span`` apart, the pad's cone under another name and parameter) certifies, verifies and
round-trips through Parquet and JSON Lines with no change elsewhere: its rows equal the pad's.

It runs in a fresh interpreter, so that registering it changes no other test's registry.
"""

import json
import subprocess
import sys
from pathlib import Path

SCRIPT = r'''
import json, sys
import pyarrow.parquet as pq
sys.path.insert(0, sys.argv[1])
import edge_model  # registers "edge"
from qualgrasp.certify import Contact, Grasp, certify_grasp, verify
from qualgrasp.certify.batch import certify_file, random_grasp_table, verify_file
from qualgrasp.certify.files import table_values
from qualgrasp.certify.quality import epsilon

out = sys.argv[2]
pads = [v for v in table_values(random_grasp_table(3, 200, n_contacts=3, model="pad"))]
edges = json.loads(json.dumps(pads).replace('"pad"', '"edge"').replace('"width"', '"span"'))
summary = {}
for name, rows in (("pad", pads), ("edge", edges)):
    for fmt in ("jsonl", "parquet"):
        src = f"{out}/{name}.jsonl"
        with open(src, "w") as fh:
            fh.writelines(json.dumps(r) + "\n" for r in rows)
        res = f"{out}/{name}-results.{fmt}"
        certify_file(src, res, quality=True, workers=1)
        if fmt == "parquet":
            table = pq.read_table(res).to_pylist()
        else:
            table = [json.loads(line) for line in open(res)]
        summary[f"{name}-{fmt}"] = table
        summary[f"{name}-{fmt}-verify"] = len(verify_file(res, src, workers=1).failures)
g = Grasp((Contact((1, 0.3), (-1, 0), "edge", mu=0.5, span=0.4), Contact((-1, 0), (1, 0), "edge", mu=0.5, span=0.4)))
p = Grasp((Contact((1, 0.3), (-1, 0), "pad", mu=0.5, width=0.4), Contact((-1, 0), (1, 0), "pad", mu=0.5, width=0.4)))
r, q = certify_grasp(g), certify_grasp(p)
summary["one"] = [[r.force.status, r.force.margin, r.form.status, epsilon(g, "L1").lo, bool(r.verified)],
                  [q.force.status, q.force.margin, q.form.status, epsilon(p, "L1").lo, bool(q.verified)]]
print(json.dumps(summary, default=str))
'''


def test_a_model_declared_outside_the_package_certifies_like_the_pad(tmp_path):
    data = Path(__file__).parent / "data"
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(data), str(tmp_path)], capture_output=True,
                         text=True, timeout=900)
    assert run.returncode == 0, run.stderr[-3000:]
    s = json.loads(run.stdout.strip().splitlines()[-1])
    edge_one, pad_one = s["one"]
    assert edge_one == pad_one and edge_one[0] == "closure" and edge_one[-1]
    for fmt in ("jsonl", "parquet"):
        pads, edges = s[f"pad-{fmt}"], s[f"edge-{fmt}"]
        assert len(pads) == len(edges) == 200
        assert s[f"edge-{fmt}-verify"] == 0 and s[f"pad-{fmt}-verify"] == 0
        assert {r["status"] for r in edges} >= {"closure", "no_closure"}
        for a, b in zip(pads, edges):
            assert a == b, {k: (a[k], b[k]) for k in a if a[k] != b.get(k)}

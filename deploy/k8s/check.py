"""Checks the Kubernetes manifests in this folder: they parse as YAML, are batch/v1 Jobs with
the fields a cluster requires, and the render Job is an Indexed Job whose shard count matches
its completions. (No cluster runs here; this is the schema check.)"""

import re
import sys
from pathlib import Path

import yaml

here = Path(__file__).parent
errors = []


def need(cond, what):
    if not cond:
        errors.append(what)


def job(path):
    doc = yaml.safe_load(path.read_text())
    need(isinstance(doc, dict), f"{path.name}: not a YAML mapping")
    need(doc.get("apiVersion") == "batch/v1", f"{path.name}: apiVersion must be batch/v1")
    need(doc.get("kind") == "Job", f"{path.name}: kind must be Job")
    need(bool(doc.get("metadata", {}).get("name")), f"{path.name}: metadata.name missing")
    spec = doc.get("spec", {})
    pod = spec.get("template", {}).get("spec", {})
    need(pod.get("restartPolicy") in ("Never", "OnFailure"),
         f"{path.name}: a Job's pods need restartPolicy Never or OnFailure")
    containers = pod.get("containers") or []
    need(len(containers) == 1, f"{path.name}: one container expected")
    c = containers[0] if containers else {}
    need(bool(c.get("name")) and bool(c.get("image")), f"{path.name}: container name and image")
    mounts = {m.get("name") for m in c.get("volumeMounts", [])}
    volumes = {v.get("name") for v in pod.get("volumes", [])}
    need(mounts <= volumes and mounts, f"{path.name}: every volumeMount needs a volume")
    return spec, " ".join(c.get("command", []) + c.get("args", []))


spec, command = job(here / "render-job.yaml")
need(spec.get("completionMode") == "Indexed", "render-job.yaml: completionMode must be Indexed")
n = spec.get("completions")
need(isinstance(n, int) and n >= 1, "render-job.yaml: completions must be a count")
need(spec.get("parallelism", n) <= n, "render-job.yaml: parallelism above completions")
shard = re.search(r'--shard "\$JOB_COMPLETION_INDEX/(\d+)"', command)
need(shard is not None, "render-job.yaml: the command must pass --shard \"$JOB_COMPLETION_INDEX/N\"")
if shard:
    need(int(shard.group(1)) == n, f"render-job.yaml: --shard N ({shard.group(1)}) != completions ({n})")
need("part-$JOB_COMPLETION_INDEX.plf" in command, "render-job.yaml: each pod writes its own .plf part")
_, merge = job(here / "merge-job.yaml")
need("pathlab merge" in merge and "part-*.plf" in merge, "merge-job.yaml: must merge the parts")

if errors:
    for e in errors:
        print(f"error: {e}", file=sys.stderr)
    sys.exit(1)
print(f"k8s: render-job.yaml ({n} indexed shards) and merge-job.yaml are valid Jobs")

"""docs/scale-out.md shows the repository's own Slurm scripts and Kubernetes manifests, verbatim,
and the manifests are valid YAML with the fields the docs rely on (no cluster needed)."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from conftest import ROOT

DOC = (ROOT / "docs" / "scale-out.md").read_text()
FILES = {
    "docs/slurm/shards.sbatch": "bash",
    "docs/slurm/merge.sbatch": "bash",
    "docs/k8s/shards.yaml": "yaml",
    "docs/k8s/merge.yaml": "yaml",
}


def blocks(lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", DOC, flags=re.S | re.M)


def test_the_docs_show_the_files_verbatim():
    for path, lang in FILES.items():
        text = (ROOT / path).read_text()
        assert text in blocks(lang), f"docs/scale-out.md does not show {path} verbatim"
        assert path in DOC, f"docs/scale-out.md does not name {path}"


def test_slurm_scripts_agree_with_each_other():
    shards = (ROOT / "docs/slurm/shards.sbatch").read_text()
    merge = (ROOT / "docs/slurm/merge.sbatch").read_text()
    # The part names the array writes are those the merge reads: five digits.
    assert "printf 'parts/%s-%05d.json'" in shards
    assert 'parts/"$name"-?????.json' in merge
    # The study's shard count is passed explicitly (a re-submitted task knows it).
    assert '--shard env --shards "$shards"' in shards
    assert "#SBATCH --array=0-" in shards


def test_kubernetes_manifests():
    shards = list(yaml.safe_load_all((ROOT / "docs/k8s/shards.yaml").read_text()))
    (merge,) = list(yaml.safe_load_all((ROOT / "docs/k8s/merge.yaml").read_text()))
    pvc, job = shards
    assert pvc["apiVersion"] == "v1" and pvc["kind"] == "PersistentVolumeClaim"
    assert "ReadWriteMany" in pvc["spec"]["accessModes"]
    claim = pvc["metadata"]["name"]

    assert job["apiVersion"] == "batch/v1" and job["kind"] == "Job"
    spec = job["spec"]
    assert spec["completionMode"] == "Indexed"
    n = spec["completions"]
    assert isinstance(n, int) and spec["parallelism"] == n and spec["backoffLimitPerIndex"] >= 1
    pod = spec["template"]["spec"]
    assert pod["restartPolicy"] == "Never"
    (c,) = pod["containers"]
    assert c["command"] == ["sh", "-c"]
    cmd = " ".join(c["args"])
    assert "--shard env" in cmd and f"--shards {n}" in cmd
    m = re.search(r"--threads (\d+)", cmd)
    assert m and c["resources"]["requests"]["cpu"] == m.group(1)
    assert "printf '/parts/fig3-%05d.json' \"$JOB_COMPLETION_INDEX\"" in cmd
    (mount,) = c["volumeMounts"]
    assert mount["mountPath"] == "/parts"
    (vol,) = pod["volumes"]
    assert vol["name"] == mount["name"] and vol["persistentVolumeClaim"]["claimName"] == claim

    assert merge["apiVersion"] == "batch/v1" and merge["kind"] == "Job"
    assert merge["spec"]["backoffLimit"] == 0
    mpod = merge["spec"]["template"]["spec"]
    assert mpod["restartPolicy"] == "Never"
    (mc,) = mpod["containers"]
    margs = " ".join(mc["args"])
    assert "scatterloc merge" in margs and "/parts/fig3-?????.json" in margs
    assert mc["image"] == c["image"]
    (mvol,) = mpod["volumes"]
    assert mvol["persistentVolumeClaim"]["claimName"] == claim
    assert mc["volumeMounts"][0]["mountPath"] == "/parts"

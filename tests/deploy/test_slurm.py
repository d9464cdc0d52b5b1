"""Studies on a real Slurm scheduler (issue 28): the docs' own scripts (docs/slurm/*.sbatch, the
same files) submitted as job arrays to the single-node cluster of scripts/slurm-local.sh, the
docs' merge step, and `scatterloc slurm submit`; the merged results equal the unsharded runs
bit for bit (timing fields aside), a failed array task makes the merge a named error listing the
missing shard, and re-submitting that task alone (--array=K) completes the set.

Run by scripts/test.sh as `bash scripts/slurm-local.sh run -- pytest tests/deploy`; needs
SLURM_CONF (set by slurm-local.sh)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from conftest import ROOT, assert_bitwise, load, run, strip_timing

SHARDS = ROOT / "docs" / "slurm" / "shards.sbatch"
MERGE = ROOT / "docs" / "slurm" / "merge.sbatch"

# A fast-profile [S] Fig. 3 study with two filters: 64 trajectories = 4 chunks of 16 per
# trajectory, so 4 shards hold one chunk of each trajectory.
MC = ["montecarlo", "--trajectory", "all", "--runs", "64", "--noise-runs", "2", "--dt", "0.1",
      "--duration", "3", "--filters", "ekf,ukf", "--seed", "5"]
# A small [A] Fig. 4 sweep: 8 realisations.
ROC = ["mtl", "roc", "--experiment", "vb", "--realizations", "8", "--seed", "2"]
# Several people (issue 41): 2 walkers, 8 runs of 2 s, PMB and GNN.
MULTI = ["montecarlo", "--targets", "2", "--runs", "8", "--duration", "2", "--seed", "3"]


@pytest.fixture(scope="module", autouse=True)
def cluster() -> None:
    if "SLURM_CONF" not in os.environ:
        pytest.fail("no Slurm cluster: run `bash scripts/slurm-local.sh run -- pytest tests/deploy`")
    out = subprocess.run(["sinfo", "-h", "-o", "%T"], capture_output=True, text=True, timeout=30)
    assert out.stdout.split() and set(out.stdout.split()) <= {"idle", "mixed", "allocated"}, out


def sbatch_wait(cwd: Path, cli: Path, *args: str) -> subprocess.CompletedProcess[str]:
    """`sbatch --wait ARGS` in ``cwd`` with the CLI under test as SCATTERLOC."""
    return run(["sbatch", "--wait", *args], cwd, env={"SCATTERLOC": str(cli)}, timeout=600)


@pytest.fixture(scope="module")
def reference(cli: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[dict, bytes]]:
    """The unsharded runs of the two studies: (JSON, PNG figure) each, computed once."""
    work = tmp_path_factory.mktemp("unsharded")
    out = {}
    for name, study in (("mc", MC), ("roc", ROC), ("multi", MULTI)):
        r = run([str(cli), *study, "--json", f"{name}.json", "--out", f"{name}.png"], work)
        assert r.returncode == 0, r.stderr
        out[name] = (load(work / f"{name}.json"), (work / f"{name}.png").read_bytes())
    return out


@pytest.mark.parametrize("study, name", [(MC, "mc"), (ROC, "roc"), (MULTI, "multi")])
def test_array_and_merge_equal_the_unsharded_run(
    cli: Path, tmp_path: Path, reference: dict, study: list[str], name: str
):
    t0 = time.perf_counter()
    want, png = reference[name]
    r = sbatch_wait(tmp_path, cli, "--array=0-3", "--cpus-per-task=1", str(SHARDS), name, "4", *study)
    assert r.returncode == 0, r.stdout + r.stderr
    parts = sorted((tmp_path / "parts").glob(f"{name}-*.json"))
    assert [p.name for p in parts] == [f"{name}-{i:05d}.json" for i in range(4)]
    r = sbatch_wait(tmp_path, cli, str(MERGE), name, "--json", "merged.json", "--out", "merged.png")
    assert r.returncode == 0, r.stdout + r.stderr
    assert_bitwise(strip_timing(load(tmp_path / "merged.json")), strip_timing(want))
    assert (tmp_path / "merged.png").read_bytes() == png
    print(f"{name}: array of 4 + merge on Slurm: {time.perf_counter() - t0:.1f} s")


def test_a_failed_task_is_named_and_resubmitting_it_completes_the_set(
    cli: Path, tmp_path: Path, reference: dict
):
    want = reference["mc"][0]
    # Task 2 dies (a node failure, an out-of-memory kill): the docs' script runs $SCATTERLOC,
    # here a wrapper that exits 3 for task 2 and runs the CLI for the others.
    crashing = tmp_path / "crashing-scatterloc"
    crashing.write_text(
        "#!/bin/sh\n"
        'if [ "$SLURM_ARRAY_TASK_ID" = 2 ]; then echo "task 2: simulated crash" >&2; exit 3; fi\n'
        f'exec "{cli}" "$@"\n'
    )
    crashing.chmod(0o755)
    r = sbatch_wait(tmp_path, crashing, "--array=0-3", "--cpus-per-task=1", str(SHARDS), "mc", "4", *MC)
    assert r.returncode != 0, "sbatch --wait must report the failed task"
    assert "simulated crash" in next(tmp_path.glob("shard-*-2.log")).read_text()
    assert sorted(p.name for p in (tmp_path / "parts").iterdir()) == [
        "mc-00000.json", "mc-00001.json", "mc-00003.json"]
    r = sbatch_wait(tmp_path, cli, str(MERGE), "mc", "--json", "merged.json")
    assert r.returncode != 0
    merge_log = next(tmp_path.glob("merge-*.log")).read_text()
    assert "missing parts: shard 2 of 4 (3 of 4 given)" in merge_log, merge_log
    assert not (tmp_path / "merged.json").exists()

    # The failed task alone, with the same arguments: the set is complete.
    r = sbatch_wait(tmp_path, cli, "--array=2", "--cpus-per-task=1", str(SHARDS), "mc", "4", *MC)
    assert r.returncode == 0, r.stdout + r.stderr
    r = sbatch_wait(tmp_path, cli, str(MERGE), "mc", "--json", "merged.json")
    assert r.returncode == 0, r.stdout + r.stderr
    assert_bitwise(strip_timing(load(tmp_path / "merged.json")), strip_timing(want))


def job_state(job: str) -> str:
    out = subprocess.run(["scontrol", "show", "job", job], capture_output=True, text=True, timeout=30).stdout
    states = {w.split("=", 1)[1] for w in out.split() if w.startswith("JobState=")}
    return ",".join(sorted(states))


def test_slurm_submit(cli: Path, tmp_path: Path, reference: dict):
    want, png = reference["mc"]
    work = tmp_path / "study"
    work.mkdir()
    r = run([str(cli), "slurm", "submit", "--shards", "4", "--name", "fig3", "--dir", str(work),
             "--cpus-per-task", "1", "--out", "fig3.png", "--", *MC], tmp_path)
    assert r.returncode == 0, r.stderr
    s = json.loads(r.stdout)
    assert s["shards"] == 4 and s["name"] == "fig3"
    assert s["json"] == str(work / "fig3.json") and s["out"] == str(work / "fig3.png")
    assert s["parts"] == str(work / "parts" / "fig3-?????.json")
    # The scripts it wrote are the docs' own.
    assert Path(s["scripts"][0]).read_text() == SHARDS.read_text()
    assert Path(s["scripts"][1]).read_text() == MERGE.read_text()
    deadline = time.monotonic() + 300
    while (state := job_state(s["merge_job"])) in {"PENDING", "RUNNING", "CONFIGURING", ""}:
        assert time.monotonic() < deadline, f"merge job {s['merge_job']} still {state}"
        time.sleep(1)
    assert state == "COMPLETED", f"merge job {s['merge_job']}: {state}"
    assert set(job_state(s["shards_job"]).split(",")) == {"COMPLETED"}
    assert_bitwise(strip_timing(load(work / "fig3.json")), strip_timing(want))
    assert (work / "fig3.png").read_bytes() == png
    assert len(list(work.glob(f"shard-{s['shards_job']}-*.log"))) == 4
    assert (work / f"merge-{s['merge_job']}.log").exists()


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--shards", "4", "--", "crlb-map", "--scenario", "s.json", "--out", "m.png"], "not a study that runs in shards"),
        (["--shards", "4", "--", "montecarlo", "--json", "x.json"], "--json is set by slurm submit"),
        (["--shards", "4", "--", "montecarlo", "--shard", "1/4"], "--shard is set by slurm submit"),
        (["--shards", "4", "--", "montecarlo", "--runz", "3"], "the study after --"),
        (["--shards", "0", "--", "montecarlo"], "--shards: 0 is outside"),
        (["--shards", "4", "--name", "a/b", "--", "montecarlo"], "--name"),
        (["--shards", "4", "--json", "x.txt", "--", "montecarlo"], "--json"),
    ],
)
def test_slurm_submit_refuses_bad_input_before_submitting(cli: Path, tmp_path: Path, args: list[str], needle: str):
    before = subprocess.run(["squeue", "-h", "-o", "%i"], capture_output=True, text=True, timeout=30).stdout
    r = run([str(cli), "slurm", "submit", "--dir", str(tmp_path), *args], tmp_path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert needle in r.stderr, r.stderr
    after = subprocess.run(["squeue", "-h", "-o", "%i"], capture_output=True, text=True, timeout=30).stdout
    assert after == before
    assert not (tmp_path / "slurm").exists()

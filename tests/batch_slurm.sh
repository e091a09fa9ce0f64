#!/usr/bin/env bash
# End-to-end test of `meshmorph batch --slurm` on a private single-node Slurm cluster
# (docs/batch.md, "How the Slurm path was tested"). Needs root and Debian's slurm-wlm and munge
# (apt-get install --no-install-recommends slurm-wlm munge); exits 77 (skipped) without them.
# Starts munged, slurmctld and slurmd on 127.0.0.1 with every file in a temporary folder and
# random private ports, submits the generated job array and gather step with the generated submit script,
# waits for them, and checks that the gathered summary and every output equal a local run's.
# Stops everything it started (by pid) on exit.
#
#   tests/batch_slurm.sh [build/native/native/meshmorph]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
meshmorph=$(realpath "${1:-$here/build/native/native/meshmorph}")
for tool in munged slurmctld slurmd sbatch squeue python3; do
  command -v "$tool" >/dev/null || { echo "batch_slurm: $tool not installed: skipped"; exit 77; }
done
[ "$(id -u)" = 0 ] || { echo "batch_slurm: needs root (munged, slurmd): skipped"; exit 77; }
[ -x "$meshmorph" ] || { echo "batch_slurm: no $meshmorph (scripts/build native)"; exit 1; }

work=$(mktemp -d /tmp/mm-batch-slurm.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  sleep 1
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  if [ "${keep:-0}" = 1 ]; then echo "batch_slurm: kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT
keep=1
started=$(date +%s)

# --- munge
mkdir -p "$work/munge" && chmod 700 "$work/munge"
mungekey --create --keyfile="$work/munge/munge.key" >/dev/null 2>&1 ||
  dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/munge.socket" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" --seed-file="$work/munge/munged.seed"
for _ in $(seq 50); do [ -s "$work/munge/munged.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/munge/munged.pid")")

# --- slurm: one node, this host, on 127.0.0.1, private ports and folders
host=$(hostname -s)
cpus=$(nproc)
port=$(( 20000 + (RANDOM % 2000) * 2 ))  # two private ports (parallel runs on one machine)
mkdir -p "$work/slurm/state" "$work/slurm/spool"
cat >"$work/slurm/slurm.conf" <<EOF
ClusterName=mmbatch
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.socket
StateSaveLocation=$work/slurm/state
SlurmdSpoolDir=$work/slurm/spool
SlurmctldPidFile=$work/slurm/slurmctld.pid
SlurmdPidFile=$work/slurm/slurmd.pid
SlurmctldLogFile=$work/slurm/slurmctld.log
SlurmdLogFile=$work/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=batch Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$work/slurm/slurm.conf"
slurmctld -i
slurmd
for _ in $(seq 100); do [ -s "$work/slurm/slurmctld.pid" ] && [ -s "$work/slurm/slurmd.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/slurm/slurmctld.pid")" "$(cat "$work/slurm/slurmd.pid")")
for _ in $(seq 100); do
  sinfo -h -o %T 2>/dev/null | grep -qE "idle|mixed" && break
  sleep 0.2
done
sinfo -h -o %T | grep -qE "idle|mixed" || { echo "batch_slurm: the node did not come up"; tail -20 "$work/slurm/slurmctld.log" "$work/slurm/slurmd.log"; exit 1; }
echo "batch_slurm: munge + slurm up in $(( $(date +%s) - started )) s"

# --- the batch: every Fox clip onto itself and wolf0, 5 fps, 3 frames (6 jobs), and a bar edit
mkdir -p "$work/run" "$work/local"
manifest() {
  cat <<EOF
{ "summary": "out/summary.json",
  "retarget": [ { "source": "$here/data/anim/Fox/glTF-Binary/Fox.glb", "clips": "*",
                  "targets": [ "$here/data/anim/Fox/glTF-Binary/Fox.glb",
                               { "path": "$here/data/anim/wolf0.ply", "joints": "$here/data/joints/wolf0_joints.json" } ],
                  "options": { "fps": 5, "last_frame": 3, "num_singularities": 120, "num_collocation": 600, "surface_descriptors": 100 },
                  "output": "out/retarget/{target}/{clip}.glb" } ],
  "edit": [ { "input": "$here/data/edit/bar.ply", "specs": ["$here/data/specs/bar_bend.json", "$here/data/specs/bar_twist.json"],
              "output": "out/edit/{spec}.ply" } ] }
EOF
}
manifest >"$work/run/lib.json"
manifest >"$work/local/lib.json"
(cd "$work/local" && "$meshmorph" batch lib.json --jobs 2 --quiet)
(cd "$work/run" && "$meshmorph" batch lib.json --slurm --shards 3 --jobs 1)
"$work/run/out/summary.slurm-submit.sh"
for _ in $(seq 600); do
  [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
  sleep 0.5
done
[ -z "$(squeue -h -o %i)" ] || { echo "batch_slurm: jobs still queued after 300 s"; squeue; exit 1; }
ls "$work/run/out/"summary.slurm-*.out >/dev/null
# Every task writes its shard summary as its last act. If one is missing, Slurm did not run the task
# here (a container that cannot launch job steps): say so and show why, but do not call it our bug.
shards_done=$(ls "$work/run/out/"summary.shard-*-of-3.json 2>/dev/null | wc -l)
if [ "$shards_done" != 3 ]; then
  echo "batch_slurm: only $shards_done of 3 array tasks wrote their shard summary; Slurm's logs:"
  for f in "$work/run/out/"*.out; do echo "--- $f"; head -c 2000 "$f"; done
  tail -n 15 "$work/slurm/slurmd.log" "$work/slurm/slurmctld.log" | cut -c1-300
  echo "batch_slurm: Slurm could not run the array here: skipped"
  exit 77
fi
[ -f "$work/run/out/summary.json" ] || { echo "batch_slurm: no gathered summary"; cat "$work/run/out/"*.out; exit 1; }

# --- compare: rows without timing (outputs relative to each folder) and every output file
python3 - "$work/run" "$work/local" <<'EOF'
import json, os, sys
def rows(d):
    d = os.path.realpath(d)  # the summaries hold physical paths (getcwd); /tmp may be a symlink
    s = json.load(open(os.path.join(d, "out/summary.json")))
    out = []
    for j in s["jobs"]:
        j = dict(j); j.pop("timing"); j["output"] = os.path.relpath(os.path.realpath(j["output"]), d); out.append(j)
    return s, out
(sr, a), (sl, b) = rows(sys.argv[1]), rows(sys.argv[2])
run_dir, local_dir = os.path.realpath(sys.argv[1]), os.path.realpath(sys.argv[2])
if a != b:
    for x, y in zip(a, b):
        if x != y:
            for k in sorted(set(x) | set(y)):
                if x.get(k) != y.get(k):
                    print("  %s: slurm %r, local %r" % (k, str(x.get(k))[:300], str(y.get(k))[:300]))
    print("  rows: slurm %d, local %d" % (len(a), len(b)))
    sys.exit("gathered rows differ from the local run's")
assert sr["counts"]["ok"] == len(a) == 8, sr["counts"]
for j in a:
    x, y = open(os.path.join(run_dir, j["output"]), "rb").read(), open(os.path.join(local_dir, j["output"]), "rb").read()
    assert x == y, j["output"] + " differs"
print("batch_slurm: %d jobs through a 3-task Slurm array + gather equal the local run (rows and bytes)" % len(a))
EOF
keep=${MM_BATCH_SLURM_KEEP:-0}
echo "batch_slurm: passed in $(( $(date +%s) - started )) s"

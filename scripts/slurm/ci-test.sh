#!/usr/bin/env bash
# The Slurm test of CI (docs/scaling.md): brings up a throwaway single-node Slurm
# (scripts/slurm/single-node.sh: Debian, root, no systemd), runs the ignored test
# `slurm_array_sweep_equals_local_sweep` of tests/shard.rs (a 64-load four-bar sweep as a
# 4-task job array plus a dependent merge job, compared with a local sweep), and takes the
# cluster down again whatever happened. Where it cannot run (not root, not Debian, Slurm's
# packages not installable) it prints "skipped: why" and exits 0. Prints its wall time.
set -uo pipefail
cd "$(dirname "$0")/../.."
start=$(date +%s)
skip() { echo "== slurm test skipped: $*"; exit 0; }
[ "$(id -u)" -eq 0 ] || skip "needs root (the single-node cluster runs slurmctld, slurmd and munged as root)"
grep -qs '^ID=debian' /etc/os-release || skip "needs Debian (scripts/slurm/single-node.sh is made for bookworm's Slurm)"
command -v apt-get >/dev/null || skip "no apt-get to install Slurm"
node=scripts/slurm/single-node.sh
export SLURM_STATE=${SLURM_STATE:-/tmp/flexrom-ci-slurm}
# a small node: the test's 4 tasks of 1 CPU each fit on any machine
export SLURM_CPUS=${SLURM_CPUS:-4}
"$node" install >/dev/null 2>&1 || skip "cannot install Slurm's packages (slurmctld slurmd slurm-client munge; no network?)"
trap '"$node" down >/dev/null 2>&1 || true' EXIT
"$node" up >/dev/null || { echo "== slurm test FAILED: the single-node cluster did not come up"; exit 1; }
# shellcheck disable=SC1091
source "$SLURM_STATE/env"
echo "== slurm test: cluster up after $(( $(date +%s) - start )) s"
HDF5_USE_FILE_LOCKING=FALSE cargo test --release --test shard -- --ignored --nocapture slurm_array_sweep_equals_local_sweep
rc=$?
echo "== slurm test: $( [ $rc -eq 0 ] && echo passed || echo FAILED ) in $(( $(date +%s) - start )) s"
exit $rc

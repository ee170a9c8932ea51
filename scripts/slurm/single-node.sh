#!/usr/bin/env bash
#
# Vendored verbatim (apart from this note) from the flexrom team's shared CI folder,
# ../shared/ci/slurm-single-node.sh (2026-11-25), whose header below describes it as the
# script a project's CI copies and calls (`ci/slurm-single-node.sh install|up|test|down`).
# CI runs on a clean clone where that folder does not exist, hence this copy; used by
# scripts/slurm/ci-test.sh.
#
# slurm-single-node.sh -- throwaway single-node Slurm cluster for CI and for
# developers who want to test job-array sweeps locally.
#
# Made for Debian bookworm (Slurm 22.05) machines and containers WITHOUT
# systemd: nothing is registered as a service.  munged, slurmctld and slurmd
# run as plain background daemons with a private config, munge key, munge
# socket, spool, state, logs and PID records under $SLURM_STATE; /etc/slurm
# and /etc/munge are not touched.  No slurmdbd: finished jobs are logged with
# jobcomp/filetxt to $SLURM_STATE/jobcomp.log instead of sacct.
#
# Usage: slurm-single-node.sh install|up|test|down|all|status
#   install  apt-get install slurmctld slurmd slurm-client munge (skipped when
#            already installed)                                       [root]
#   up       write slurm.conf, create the munge key, start the daemons, wait
#            for the node to be idle, print `export SLURM_CONF=...` on stdout
#            (all other messages go to stderr) and write it to $SLURM_STATE/env.
#            Says so and does nothing if the cluster is already up.  [root]
#   test     self-test: 8-task job array through sbatch (polled with squeue),
#            per-task states from jobcomp/filetxt, and one `srun hostname`.
#            Exits non-zero on failure.
#   down     scancel all jobs, stop the daemons by the PIDs recorded in
#            $SLURM_STATE (never by name), remove $SLURM_STATE.  Safe when
#            nothing is up.                                           [root]
#   all      install, up, test, down (down runs even if up/test fail).
#   status   show the recorded daemons and sinfo.
#
# How a project's CI would use it:
#   ci/slurm-single-node.sh install
#   ci/slurm-single-node.sh up            # or: eval "$(ci/slurm-single-node.sh up)"
#   source "${SLURM_STATE:-/tmp/flexrom-slurm}/env"    # exports SLURM_CONF
#   jobid=$(sbatch --parsable --job-name=sweep --array=0-7 \
#                  --output=out_%A_%a.txt sweep_task.sh)
#   while [ -n "$(squeue -h -j "$jobid" -t PD,CF,R,CG,S)" ]; do sleep 1; done
#   grep ' Name=sweep ' "$SLURM_STATE/jobcomp.log"    # a line per task:
#                          # ... JobState=COMPLETED ... ArrayTaskId=3 ... ExitCode=0:0
#   ci/slurm-single-node.sh down          # also in an `always`/cleanup step
#
# Settings (environment, defaults in brackets):
#   SLURM_STATE        [/tmp/flexrom-slurm]  private state dir; removed by `down`
#   SLURM_CPUS         [8]     CPUs the node advertises (may exceed real cores)
#   SLURM_MEM_MB       [90% of MemTotal]  RealMemory the node advertises
#   SLURM_CTLD_PORT    [6817]  slurmctld port;  SLURMD_PORT [6818] slurmd port
#   SLURM_UP_TIMEOUT   [60]    seconds `up` waits for the node to become idle
#   SLURM_TEST_TIMEOUT [120]   seconds `test` waits for the job array
#
set -euo pipefail

SLURM_STATE=${SLURM_STATE:-/tmp/flexrom-slurm}
SLURM_CPUS=${SLURM_CPUS:-8}
SLURM_CTLD_PORT=${SLURM_CTLD_PORT:-6817}
SLURMD_PORT=${SLURMD_PORT:-6818}
SLURM_UP_TIMEOUT=${SLURM_UP_TIMEOUT:-60}
SLURM_TEST_TIMEOUT=${SLURM_TEST_TIMEOUT:-120}

PACKAGES=(slurmctld slurmd slurm-client munge)
DAEMONS=(munged slurmctld slurmd)         # start order; stopped in reverse
MARKER=.slurm-single-node                 # `down` only deletes dirs holding this
PROG=${0##*/}
SELF=$(realpath -- "${BASH_SOURCE[0]}")

CONF=$SLURM_STATE/slurm.conf
ENVFILE=$SLURM_STATE/env
MUNGE_DIR=$SLURM_STATE/munge
MUNGE_SOCKET=$MUNGE_DIR/munge.socket.2
PID_DIR=$SLURM_STATE/pids
LOG_DIR=$SLURM_STATE/log
JOBCOMP=$SLURM_STATE/jobcomp.log

T0=$(date +%s.%N)

log()  { printf '[%s %6.1fs] %s\n' "$PROG" "$(elapsed)" "$*" >&2; }
warn() { log "WARNING: $*"; }
die()  { log "ERROR: $*"; exit 1; }
elapsed() { awk -v a="$T0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }

need_root() { [ "$(id -u)" -eq 0 ] || die "'$1' needs root (run it with sudo)"; }

check_state_path() {
    case $SLURM_STATE in
        /?*) ;;
        *) die "SLURM_STATE must be an absolute path (got '$SLURM_STATE')" ;;
    esac
    case $SLURM_STATE in
        *[[:space:]]*) die "SLURM_STATE must not contain whitespace" ;;
    esac
    [ "$(realpath -m "$SLURM_STATE")" != / ] || die "SLURM_STATE must not be /"
    local v
    for v in SLURM_CPUS SLURM_CTLD_PORT SLURMD_PORT SLURM_UP_TIMEOUT SLURM_TEST_TIMEOUT; do
        [[ ${!v} =~ ^[1-9][0-9]*$ ]] || die "$v must be a positive integer (got '${!v}')"
    done
    [[ ${SLURM_MEM_MB:-1} =~ ^[1-9][0-9]*$ ]] || die "SLURM_MEM_MB must be a positive integer"
}

# ---------------------------------------------------------------- processes

# Prints the start time (field 22 of /proc/PID/stat) of a live process; fails
# for a missing or zombie process.  The start time guards against PID reuse;
# zombies count as dead (some container inits are slow to reap them).
proc_start() {
    local stat
    local -a f
    stat=$(cat "/proc/$1/stat" 2>/dev/null) || return 1
    read -ra f <<< "${stat##*) }"     # drop "pid (comm) " (comm may hold spaces)
    case ${f[0]:-} in Z|X|x|"") return 1 ;; esac
    [ -n "${f[19]:-}" ] && printf '%s\n' "${f[19]}"
}

# Is the daemon recorded as $1 running, with the same PID, name and start time?
recorded_alive() {
    local rec=$PID_DIR/$1 pid start comm now
    [ -r "$rec" ] || return 1
    read -r pid start < "$rec" || return 1
    [[ $pid =~ ^[0-9]+$ ]] || return 1
    comm=$(cat "/proc/$pid/comm" 2>/dev/null) || return 1
    [ "$comm" = "$1" ] || return 1
    now=$(proc_start "$pid") || return 1
    [ "$now" = "$start" ]
}

recorded_pid() { local pid _; read -r pid _ < "$PID_DIR/$1"; printf '%s\n' "$pid"; }

# Stop the daemon recorded as $1: SIGTERM, wait, then SIGKILL.  Only ever the
# recorded PID, and only if it is still the process that was recorded.
stop_recorded() {
    local name=$1 pid i
    [ -e "$PID_DIR/$name" ] || return 0
    if ! recorded_alive "$name"; then
        log "$name: recorded PID $(recorded_pid "$name" 2>/dev/null || echo '?') is not running"
        rm -f "$PID_DIR/$name"
        return 0
    fi
    pid=$(recorded_pid "$name")
    log "stopping $name (PID $pid)"
    kill -TERM "$pid" 2>/dev/null || true
    for ((i = 0; i < 100; i++)); do          # up to 10 s
        recorded_alive "$name" || break
        sleep 0.1
    done
    if recorded_alive "$name"; then
        warn "$name (PID $pid) ignored SIGTERM; sending SIGKILL"
        kill -KILL "$pid" 2>/dev/null || true
        for ((i = 0; i < 50; i++)); do
            recorded_alive "$name" || break
            sleep 0.1
        done
    fi
    recorded_alive "$name" && die "could not stop $name (PID $pid)"
    rm -f "$PID_DIR/$name"
}

# After starting a daemon that writes pidfile $2: wait for it, check the
# process is really $1, and record "PID STARTTIME" in $PID_DIR/$1.
record_daemon() {
    local name=$1 pidfile=$2 logfile=$3 pid="" start i
    for ((i = 0; i < 150; i++)); do          # up to 15 s
        if [ -s "$pidfile" ]; then
            read -r pid < "$pidfile" || true
            if [[ $pid =~ ^[0-9]+$ ]] && [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$name" ]; then
                start=$(proc_start "$pid") && break
            fi
        fi
        sleep 0.1
    done
    if [ -z "${start:-}" ]; then
        show_log "$logfile"
        die "$name did not start (no live process in $pidfile)"
    fi
    printf '%s %s\n' "$pid" "$start" > "$PID_DIR/$name"
    log "$name started (PID $pid)"
}

show_log() {
    [ -s "$1" ] || return 0
    log "last lines of $1:"
    tail -n 25 "$1" | sed 's/^/    | /' >&2
}

show_all_logs() {
    local f
    for f in "$LOG_DIR"/*.log; do [ -e "$f" ] && show_log "$f"; done
    return 0
}

# Full path of a daemon binary (they live in /usr/sbin, often not in a user's PATH).
sbin() {
    local p
    p=$(PATH=$PATH:/usr/sbin:/sbin command -v "$1") || die "$1 not found; run '$PROG install' first"
    printf '%s\n' "$p"
}

port_in_use() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }

# Slurm client commands can hang when slurmctld is unhealthy: always bound them.
sinfo_node_state() { timeout 5 sinfo -h -N -n "$NODE" -o '%T' 2>/dev/null | head -n 1; }

load_env() {
    [ -r "$ENVFILE" ] || die "no cluster is up (missing $ENVFILE); run '$PROG up' first"
    # shellcheck disable=SC1090
    source "$ENVFILE"
    NODE=$(awk -F'[= ]' '/^NodeName=/ { print $2; exit }' "$SLURM_CONF")
}

is_up() {
    local d
    [ -f "$SLURM_STATE/$MARKER" ] || return 1
    for d in "${DAEMONS[@]}"; do recorded_alive "$d" || return 1; done
}

# ---------------------------------------------------------------- install

cmd_install() {
    local p missing=() aptlog
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' \
            || missing+=("$p")
    done
    if [ ${#missing[@]} -eq 0 ]; then
        log "install: ${PACKAGES[*]} already installed ($(dpkg-query -W -f='${Version}' slurmctld)); skipping"
        return 0
    fi
    need_root install
    command -v apt-get >/dev/null || die "apt-get not found: this script supports Debian/Ubuntu only"
    log "install: apt-get install ${missing[*]} ..."
    aptlog=$(mktemp)
    export DEBIAN_FRONTEND=noninteractive
    if ! { apt-get update -qq &&
           apt-get install -y -qq --no-install-recommends -o Dpkg::Use-Pty=0 "${PACKAGES[@]}"; } \
           > "$aptlog" 2>&1; then
        tail -n 40 "$aptlog" >&2
        rm -f "$aptlog"
        die "apt-get failed"
    fi
    rm -f "$aptlog"
    log "install: done ($(dpkg-query -W -f='${Version}' slurmctld))"
}

# ---------------------------------------------------------------- up

write_conf() {
    local host=$1 mem=$2
    cat > "$CONF" <<EOF
# Generated by $PROG: single-node test cluster, state in $SLURM_STATE
ClusterName=flexrom
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$SLURM_CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCKET
MailProg=/bin/true
MpiDefault=none
# no cgroups: plain process tracking, no task containment
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
# no slurmdbd: completed jobs (one line per array task) go to a text file
JobCompType=jobcomp/filetxt
JobCompLoc=$JOBCOMP
SchedulerType=sched/backfill
# start newly submitted job arrays within ~1 s instead of the default 3 s
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
# trust the node line below instead of the detected hardware
SlurmdParameters=config_overrides
PropagateResourceLimits=NONE
ReturnToService=2
InactiveLimit=0
KillWait=5
MinJobAge=300
StateSaveLocation=$SLURM_STATE/ctld
SlurmdSpoolDir=$SLURM_STATE/slurmd
SlurmctldPidFile=$SLURM_STATE/run/slurmctld.pid
SlurmdPidFile=$SLURM_STATE/run/slurmd.pid
SlurmctldLogFile=$LOG_DIR/slurmctld.log
SlurmdLogFile=$LOG_DIR/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
NodeName=$host NodeHostname=$host NodeAddr=127.0.0.1 CPUs=$SLURM_CPUS Boards=1 SocketsPerBoard=1 CoresPerSocket=$SLURM_CPUS ThreadsPerCore=1 RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
}

start_munged() {
    id munge >/dev/null 2>&1 || die "user 'munge' does not exist (is the munge package installed?)"
    install -d -o munge -g munge -m 0755 "$MUNGE_DIR"
    # munged runs as the munge user: every folder above the state dir must let it through
    if ! runuser -u munge -- test -x "$MUNGE_DIR" 2>/dev/null; then
        die "the munge user cannot reach $MUNGE_DIR (a parent folder is not world-traversable, e.g. one made by mktemp -d); choose SLURM_STATE elsewhere or chmod o+x its parents"
    fi
    if [ ! -s "$MUNGE_DIR/munge.key" ]; then
        if command -v mungekey >/dev/null; then
            mungekey --create --keyfile="$MUNGE_DIR/munge.key" --force
        else
            dd if=/dev/urandom of="$MUNGE_DIR/munge.key" bs=1024 count=1 status=none
        fi
        log "created munge key $MUNGE_DIR/munge.key"
    fi
    chown munge:munge "$MUNGE_DIR/munge.key"
    chmod 0400 "$MUNGE_DIR/munge.key"
    runuser -u munge -- "$(sbin munged)" \
        --socket="$MUNGE_SOCKET" \
        --key-file="$MUNGE_DIR/munge.key" \
        --pid-file="$MUNGE_DIR/munged.pid" \
        --log-file="$MUNGE_DIR/munged.log" \
        --seed-file="$MUNGE_DIR/munged.seed" \
        > "$LOG_DIR/munged.out" 2>&1 || { cat "$LOG_DIR/munged.out" >&2; show_log "$MUNGE_DIR/munged.log"; die "munged failed to start"; }
    record_daemon munged "$MUNGE_DIR/munged.pid" "$MUNGE_DIR/munged.log"
    munge -n --socket="$MUNGE_SOCKET" | unmunge --socket="$MUNGE_SOCKET" >/dev/null \
        || die "munge credential round trip failed"
}

cmd_up() {
    local host mem d i state=""
    check_state_path
    if is_up; then
        log "up: already up (PIDs: $(for d in "${DAEMONS[@]}"; do printf "%s=%s " "$d" "$(recorded_pid "$d")"; done | sed "s/ $//")); nothing to do"
        load_env
        state=$(sinfo_node_state || true)
        log "up: node $NODE is ${state:-not answering}"
        cat "$ENVFILE"
        return 0
    fi
    need_root up
    for d in munged slurmctld slurmd; do sbin "$d" >/dev/null; done
    if [ -e "$SLURM_STATE" ]; then
        [ -f "$SLURM_STATE/$MARKER" ] || die "$SLURM_STATE exists but was not made by $PROG; remove it or set SLURM_STATE"
        log "up: found a stale or partial cluster in $SLURM_STATE; cleaning it up first"
        cmd_down
    fi
    for i in "$SLURM_CTLD_PORT" "$SLURMD_PORT"; do
        port_in_use "$i" && die "port $i is already in use (another Slurm?); set SLURM_CTLD_PORT/SLURMD_PORT"
    done

    host=$(hostname -s)
    [ -n "$host" ] || die "hostname -s is empty"
    if [ -n "${SLURM_MEM_MB:-}" ]; then
        mem=$SLURM_MEM_MB
    else
        mem=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
        [ "${mem:-0}" -ge 1 ] || mem=1
    fi

    log "up: state dir $SLURM_STATE, node $host, $SLURM_CPUS CPUs, ${mem} MB"
    # On failure leave the daemons and logs for inspection, and say how to clean up.
    trap 'log "up FAILED; logs are in $LOG_DIR and $MUNGE_DIR; run \"$PROG down\" to clean up"' EXIT
    install -d -m 0755 "$SLURM_STATE" "$SLURM_STATE/ctld" "$SLURM_STATE/slurmd" \
        "$SLURM_STATE/run" "$PID_DIR" "$LOG_DIR"
    install -d -m 1777 "$SLURM_STATE/scratch"
    : > "$SLURM_STATE/$MARKER"
    : > "$JOBCOMP"
    write_conf "$host" "$mem"
    printf 'export SLURM_CONF=%s\n' "$CONF" > "$ENVFILE"
    export SLURM_CONF=$CONF
    NODE=$host

    start_munged

    "$(sbin slurmctld)" -f "$CONF" > "$LOG_DIR/slurmctld.out" 2>&1 \
        || { cat "$LOG_DIR/slurmctld.out" >&2; show_log "$LOG_DIR/slurmctld.log"; die "slurmctld failed to start"; }
    record_daemon slurmctld "$SLURM_STATE/run/slurmctld.pid" "$LOG_DIR/slurmctld.log"

    "$(sbin slurmd)" -f "$CONF" > "$LOG_DIR/slurmd.out" 2>&1 \
        || { cat "$LOG_DIR/slurmd.out" >&2; show_log "$LOG_DIR/slurmd.log"; die "slurmd failed to start"; }
    record_daemon slurmd "$SLURM_STATE/run/slurmd.pid" "$LOG_DIR/slurmd.log"

    log "up: waiting (up to ${SLURM_UP_TIMEOUT}s) for node $host to be idle"
    for ((i = 0; i < SLURM_UP_TIMEOUT * 2; i++)); do
        state=$(sinfo_node_state || true)
        [ "$state" = idle ] && break
        for d in "${DAEMONS[@]}"; do
            recorded_alive "$d" || { show_all_logs; die "$d died while starting"; }
        done
        sleep 0.5
    done
    if [ "$state" != idle ]; then
        show_all_logs
        die "node $host is '${state:-not answering}', not idle, after ${SLURM_UP_TIMEOUT}s"
    fi
    trap - EXIT
    log "up: cluster ready, node $host idle. For your shell:"
    log "      source $ENVFILE     (or the line below)"
    cat "$ENVFILE"
}

# ---------------------------------------------------------------- test

# Active = not yet finished.  Prints the number of unfinished array tasks.
active_tasks() {
    local out rc=0
    out=$(timeout 5 squeue -h -r -j "$1" -o '%T' 2>&1) || rc=$?
    if [ $rc -ne 0 ]; then
        case $out in
            *"Invalid job id"*) echo 0; return 0 ;;   # already purged
            *) return 1 ;;                           # squeue hung or failed: unknown
        esac
    fi
    printf '%s\n' "$out" | grep -cvE '^(COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|PREEMPTED|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE)?$' || true
}

cmd_test() {
    local dir name jobid n i f t1 deadline lines states ok=1 host srun_out
    check_state_path
    is_up || die "no cluster is up in $SLURM_STATE; run '$PROG up' first"
    load_env
    t1=$(date +%s.%N)
    [ "$(sinfo_node_state || true)" = idle ] || warn "node $NODE is not idle: '$(sinfo_node_state || true)'"

    dir=$(mktemp -d -p "$SLURM_STATE/scratch" selftest.XXXXXX)
    chmod 0755 "$dir"
    name=selftest-${dir##*.}
    cat > "$dir/task.sh" <<'EOF'
#!/bin/bash
echo "task=${SLURM_ARRAY_TASK_ID} array_job=${SLURM_ARRAY_JOB_ID} job=${SLURM_JOB_ID} host=$(hostname) start=$(date +%s.%N)"
sleep 2
echo "end=$(date +%s.%N)"
EOF
    chmod 0755 "$dir/task.sh"

    jobid=$(timeout 30 sbatch --parsable --job-name="$name" --array=0-7 \
        --ntasks=1 --cpus-per-task=1 --time=5 \
        --chdir="$dir" --output="$dir/out_%A_%a.txt" "$dir/task.sh") \
        || die "sbatch failed"
    jobid=${jobid%%;*}
    log "test: submitted job array $jobid (8 tasks, name $name)"

    deadline=$((SECONDS + SLURM_TEST_TIMEOUT))
    while :; do
        if n=$(active_tasks "$jobid"); then
            [ "$n" -eq 0 ] && break
        else
            n='?'
        fi
        if [ $SECONDS -ge $deadline ]; then
            timeout 5 squeue -r -j "$jobid" >&2 || true
            show_all_logs
            die "job array $jobid not finished after ${SLURM_TEST_TIMEOUT}s ($n tasks left)"
        fi
        sleep 0.5
    done
    log "test: job array $jobid left the queue"

    # jobcomp/filetxt: one line per array task, written when the task ends.
    for ((i = 0; i < 40; i++)); do
        lines=$(grep -F " Name=$name " "$JOBCOMP" || true)
        [ "$(printf '%s' "$lines" | grep -c . || true)" -ge 8 ] && break
        sleep 0.25
    done
    states=$(printf '%s\n' "$lines" | grep . | sed -E 's/.*ArrayTaskId=([0-9]+).*JobState=([A-Z_]+).*|.*JobState=([A-Z_]+).*ArrayTaskId=([0-9]+).*/\1\4 \2\3/' | sort -n)
    log "test: per-task states from $JOBCOMP:"
    printf '%s\n' "$states" | sed 's/^/    task /' >&2
    if [ "$(printf '%s\n' "$states" | grep -c ' COMPLETED$' || true)" -ne 8 ]; then
        warn "expected 8 COMPLETED tasks in $JOBCOMP"
        printf '%s\n' "$lines" >&2
        ok=0
    fi

    for ((i = 0; i < 8; i++)); do
        f=$dir/out_${jobid}_$i.txt
        if [ ! -s "$f" ] || ! grep -q "^task=$i " "$f" || ! grep -q '^end=' "$f"; then
            warn "missing or incomplete output $f"
            [ -e "$f" ] && sed 's/^/    | /' "$f" >&2
            ok=0
        fi
    done
    if [ $ok -eq 1 ]; then
        log "test: all 8 outputs present and complete"
        # Informational: did the 8 tasks (2 s each) overlap, i.e. run at once?
        cat "$dir"/out_"${jobid}"_*.txt | awk -F'start=|end=' '
            /start=/ { s = $2 + 0; if (s > maxs) maxs = s; if (!mins || s < mins) mins = s }
            /^end=/  { e = $2 + 0; if (!mine || e < mine) mine = e; if (e > maxe) maxe = e }
            END { printf "test: tasks ran %s (first start to last end %.1f s)\n",
                  (maxs < mine ? "all 8 at once" : "NOT all at once"), maxe - mins }' |
            while read -r l; do log "$l"; done
    fi

    host=$(hostname)
    srun_out=$(timeout 60 srun --job-name="$name-srun" -N1 -n1 --time=1 hostname 2>&1) || {
        warn "srun hostname failed: $srun_out"; ok=0; srun_out=""; }
    if [ -n "$srun_out" ]; then
        if [ "$srun_out" = "$host" ]; then
            log "test: srun hostname -> $srun_out"
        else
            warn "srun hostname printed '$srun_out', expected '$host'"
            ok=0
        fi
    fi

    rm -rf "$dir"
    if [ $ok -ne 1 ]; then
        show_all_logs
        die "test: FAILED"
    fi
    log "test: PASSED in $(awk -v a="$t1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s"
}

# ---------------------------------------------------------------- down

cmd_down() {
    local d ids i n
    check_state_path
    if [ ! -e "$SLURM_STATE" ]; then
        log "down: nothing is up ($SLURM_STATE does not exist)"
        return 0
    fi
    [ -f "$SLURM_STATE/$MARKER" ] || die "$SLURM_STATE was not made by $PROG; not touching it"
    need_root down
    if recorded_alive slurmctld && [ -r "$ENVFILE" ]; then
        export SLURM_CONF=$CONF
        ids=$(timeout 5 squeue -h -o '%F' 2>/dev/null | sort -un | paste -sd' ' || true)
        if [ -n "${ids// /}" ]; then
            log "down: cancelling jobs: $ids"
            # shellcheck disable=SC2086
            timeout 10 scancel $ids || warn "scancel failed"
            for ((i = 0; i < 40; i++)); do       # let them drain, up to 20 s
                n=$(timeout 5 squeue -h -o '%i' 2>/dev/null) || n=unknown
                [ -z "$n" ] && break
                sleep 0.5
            done
            [ -z "$n" ] || warn "jobs still in the queue after 20 s: $(printf '%s' "$n" | paste -sd' ')"
        fi
    fi
    for ((i = ${#DAEMONS[@]} - 1; i >= 0; i--)); do
        stop_recorded "${DAEMONS[$i]}"
    done
    rm -rf "$SLURM_STATE"
    log "down: stopped; removed $SLURM_STATE"
}

# ---------------------------------------------------------------- status

cmd_status() {
    local d
    check_state_path
    if [ ! -f "$SLURM_STATE/$MARKER" ]; then
        log "status: not up ($SLURM_STATE missing)"
        return 1
    fi
    for d in "${DAEMONS[@]}"; do
        if recorded_alive "$d"; then log "status: $d running (PID $(recorded_pid "$d"))"
        else log "status: $d NOT running"; fi
    done
    load_env
    timeout 5 sinfo -N -l >&2 || warn "sinfo did not answer"
    is_up
}

# ---------------------------------------------------------------- main

main() {
    local rc=0
    case ${1:-} in
        install) cmd_install ;;
        up)      cmd_up ;;
        test)    cmd_test ;;
        down)    cmd_down ;;
        status)  cmd_status ;;
        all)
            cmd_install
            # Separate processes (set -e stays in force in each), and `down`
            # runs even when up or test fail.
            "$BASH" "$SELF" up >/dev/null && "$BASH" "$SELF" test || rc=$?
            "$BASH" "$SELF" down || { [ $rc -ne 0 ] || rc=1; }
            if [ $rc -eq 0 ]; then log "all: PASSED in $(elapsed) s"
            else log "all: FAILED (rc=$rc) after $(elapsed) s"; fi
            return $rc ;;
        -h|--help|help) sed -n '3,/^set -euo/{/^#/s/^# \{0,1\}//p}' "$SELF" ;;
        *) echo "usage: $PROG install|up|test|down|all|status  (see --help)" >&2; return 2 ;;
    esac
}

main "$@"

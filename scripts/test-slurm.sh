#!/usr/bin/env bash
# examples/cluster/slurm-submit.sh under a real, private, one-node Slurm on this machine:
#
#   1. installs Debian's slurm-wlm and munge if missing (apt-get update only when needed);
#   2. starts munged (as user munge, fresh key) and slurmctld + slurmd (as root) with a generated
#      slurm.conf: one node (`hostname`, CPUs=$(nproc)), one partition, free ports, the munge
#      socket, state, spool, logs all in a private temp dir (SLURM_CONF points there);
#   3. builds strata (release) if needed and submits a small render as SHARDS array tasks of
#      CPUS=1 each plus the merge job, with CHECKPOINT_EVERY=0 (a checkpoint after every pass);
#   4. requeues one task (`scontrol requeue JOB_TASK`) while it renders, after its first
#      checkpoint, and checks: Slurm restarted it (Restarts=1), strata stopped on the SIGTERM
#      after a pass with a checkpoint holding part of the range, the second run resumed from
#      that checkpoint and rendered only the rest (its summary counts the camera rays);
#   5. waits for the merge job and checks that the merged image is bit-identical to the
#      one-machine `strata render` of the same scene and flags: same PNG bytes, same EXR pixels
#      (every channel, decoded by a small python3 reader below, since the EXR headers differ in
#      timings and parts), strata.spp and strata.part_count as expected;
#   6. mixed CPUs: a cluster that mixes AVX-512 and AVX2-only nodes pins isa=avx2 on every node
#      (docs/robustness.md; the default is AVX-512 where the CPU has it): every array task and the
#      one-machine render run with STRATA_EMBREE_CONFIG=isa=avx2, so step 5's bit-identity covers
#      the pin. Then task SLURM_TEST_ISA_TASK's (2) range is rendered again unpinned (on an
#      AVX-512 node: Embree's AVX-512 kernels, what a node that forgot the pin runs) and
#      `strata merge` of it with the other parts must be refused, naming embree_isa on both sides.
#
# Everything it started is torn down on exit, pass or fail (jobs cancelled, daemons and job
# processes killed by pid, temp dir removed); every wait is bounded. Prints PASS or FAIL and the
# elapsed time. Needs root (daemons, apt-get). Knobs (env): SLURM_TEST_SPP (2048), SLURM_TEST_SHARDS
# (4), SLURM_TEST_SIZE (96x96), SLURM_TEST_SCENE (scenes/cornell_diffuse_path.test),
# SLURM_TEST_REQUEUE_TASK (1), SLURM_TEST_ISA_TASK (2), SLURM_TEST_TIMEOUT (seconds for the whole run, 600), STRATA (binary;
# default: build target/release/strata), SLURM_TEST_KEEP=1 keeps the temp dir for a post-mortem.
set -euo pipefail
started=$SECONDS
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SPP=${SLURM_TEST_SPP:-2048} SHARDS=${SLURM_TEST_SHARDS:-4} SIZE=${SLURM_TEST_SIZE:-96x96}
SCENE=${SLURM_TEST_SCENE:-$root/scenes/cornell_diffuse_path.test}
REQ=${SLURM_TEST_REQUEUE_TASK:-1} ISA_TASK=${SLURM_TEST_ISA_TASK:-2} TIMEOUT=${SLURM_TEST_TIMEOUT:-600}
FLAGS="--size $SIZE --seed 7"
deadline=$(( SECONDS + TIMEOUT ))

say() { echo "test-slurm: $*" >&2; }
die() { say "FAILED: $*"; exit 1; }

# Nothing from an enclosing Slurm job may leak into ours.
while read -r v; do unset "$v"; done < <(compgen -e | grep '^SLURM_' | grep -v '^SLURM_TEST_' || true)

[ "$(id -u)" = 0 ] || die "run as root (starts slurmctld, slurmd and munged, may apt-get install)"
case "$SCENE" in /*) ;; *) SCENE="$PWD/$SCENE" ;; esac
[ -f "$SCENE" ] || die "no scene $SCENE"

# ---- 1. packages ---------------------------------------------------------------------------
need=()
for c in slurmctld slurmd sbatch scontrol munged mungekey; do
  command -v "$c" >/dev/null 2>&1 || { need=(slurm-wlm munge); break; }
done
if [ ${#need[@]} -gt 0 ]; then
  say "installing ${need[*]} (Debian packages)"
  t=$SECONDS
  # Keep the packages' own services from starting (no init here, and we run our own daemons).
  made_policy=
  if [ ! -e /usr/sbin/policy-rc.d ]; then
    printf '#!/bin/sh\nexit 101\n' >/usr/sbin/policy-rc.d && chmod +x /usr/sbin/policy-rc.d && made_policy=1
  fi
  aptlog=$(mktemp /tmp/strata-slurm-apt.XXXXXX)
  update() { timeout 300 apt-get update -qq >>"$aptlog" 2>&1; }
  apt_install() {
    DEBIAN_FRONTEND=noninteractive timeout 600 apt-get install -y -qq --no-install-recommends "${need[@]}" >>"$aptlog" 2>&1
  }
  updated=''
  if ! apt-cache show slurm-wlm >/dev/null 2>&1; then update || true; updated=1; fi
  # Stale package lists (a version gone from the mirror): update once and retry.
  if ! apt_install && ! { [ -z "$updated" ] && update && apt_install; }; then
    [ -z "$made_policy" ] || rm -f /usr/sbin/policy-rc.d
    tail -n 20 "$aptlog" >&2; rm -f "$aptlog"
    die "apt-get install ${need[*]} failed"
  fi
  [ -z "$made_policy" ] || rm -f /usr/sbin/policy-rc.d
  rm -f "$aptlog"
  say "installed in $(( SECONDS - t )) s"
fi

# ---- strata ---------------------------------------------------------------------------------
if [ -z "${STRATA:-}" ]; then
  "$root/scripts/setup.sh"
  [ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
  (cd "$root" && cargo build --release --quiet --bin strata)
  STRATA="$root/target/release/strata"
fi
[ -x "$STRATA" ] || die "STRATA=$STRATA is not executable"

# ---- teardown (armed before anything starts) -------------------------------------------------
tmp=$(mktemp -d /tmp/strata-slurm.XXXXXX)
chmod 755 "$tmp"
munged_pid='' ctld_pid='' slurmd_pid='' ref_pid='' passed=''
pids_under_tmp() { # every process (but us) with its cwd or an open file in $tmp: job steps, strata
  find /proc/[0-9]*/cwd /proc/[0-9]*/fd -maxdepth 1 -lname "$tmp*" 2>/dev/null \
    | sed -E 's|^/proc/([0-9]+)/.*|\1|' | sort -u | grep -vx -e "$$" -e "$BASHPID" || true
}
stop_pids() { # TERM, up to $1 s, then KILL
  local wait=$1 p n; shift
  [ $# -gt 0 ] || return 0
  kill -TERM "$@" 2>/dev/null
  for (( n = 0; n < wait * 10; n++ )); do
    for p in "$@"; do kill -0 "$p" 2>/dev/null && break; p=; done
    [ -z "$p" ] && return 0
    sleep 0.1
  done
  kill -KILL "$@" 2>/dev/null
  return 0
}
cleanup() {
  local rc=$? n
  set +e
  trap - EXIT INT TERM
  cd /  # not in $tmp, or our own subshells would count as processes using it
  if [ -z "$passed" ] && [ -d "$tmp/log" ]; then
    say "--- diagnostics (temp dir $tmp) ---"
    for f in "$tmp"/log/*.log "$tmp"/work/ref.parts/*.log; do
      [ -f "$f" ] && { echo "== $f (tail)"; tail -n 15 "$f"; } >&2
    done
    [ -n "$ctld_pid" ] && scontrol show job -o 2>/dev/null | cut -c1-300 >&2
  fi
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    scancel --quiet --user=root 2>/dev/null
    for (( n = 0; n < 100; n++ )); do  # up to 10 s for the jobs to go
      [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
      sleep 0.1
    done
  fi
  [ -n "$ref_pid" ] && stop_pids 5 "$ref_pid"
  stop_pids 10 $slurmd_pid $ctld_pid
  # shellcheck disable=SC2046 # a list of pids
  stop_pids 5 $(pids_under_tmp)
  stop_pids 5 $munged_pid
  wait 2>/dev/null
  local left; left=$(pids_under_tmp | tr '\n' ' ')
  [ -z "$left" ] || say "WARNING: processes still using $tmp: $left"
  if [ -n "${SLURM_TEST_KEEP:-}" ]; then say "kept $tmp"; else rm -rf "$tmp"; fi
  if [ -n "$passed" ] && [ "$rc" = 0 ]; then
    echo "test-slurm: PASS ($(( SECONDS - started )) s)"
  else
    echo "test-slurm: FAIL ($(( SECONDS - started )) s)"
    [ "$rc" != 0 ] || rc=1
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'say "interrupted"; exit 130' INT TERM

left() { echo $(( deadline - SECONDS )); }
# wait_for WHAT SECONDS CMD...: polls CMD every 0.2 s, at most SECONDS (and never past the deadline).
wait_for() {
  local what=$1 secs=$2; shift 2
  local until=$(( SECONDS + secs )); [ "$until" -le "$deadline" ] || until=$deadline
  while ! "$@"; do
    [ "$SECONDS" -lt "$until" ] || die "timed out after ${secs} s waiting for $what"
    sleep 0.2
  done
}

# ---- python3 helpers: checkpoint header, EXR pixels (stdlib only) -----------------------------
cat >"$tmp/tool.py" <<'PY'
import json, struct, sys, zlib

def ckpt(path):
    """Prints 'A B T0 T1' (samples held, target range) of a strata checkpoint."""
    with open(path, "rb") as f:
        head = f.read(20)
        assert head[:8] == b"STRATACK", "not a strata checkpoint"
        (n,) = struct.unpack_from("<Q", head, 12)
        h = json.loads(f.read(n))
    print(*h["samples"], *h["target"])

def exr(path):
    """Single-part scan-line EXR (NONE, ZIPS or ZIP): (width, height, {channel: raw little-endian
    bytes, rows top to bottom}, {attribute: text} for string attributes)."""
    b = open(path, "rb").read()
    assert b[:4] == b"\x76\x2f\x31\x01", f"{path}: not an EXR"
    assert struct.unpack_from("<I", b, 4)[0] & 0x1e00 == 0, f"{path}: tiled, deep or multi-part"
    p, attrs = 8, {}
    while b[p]:
        e = b.index(0, p); name = b[p:e].decode(); p = e + 1
        e = b.index(0, p); typ = b[p:e].decode(); p = e + 1
        (n,) = struct.unpack_from("<i", b, p); p += 4
        attrs[name] = (typ, b[p:p + n]); p += n
    p += 1
    cl, q, chans = attrs["channels"][1], 0, []
    while cl[q]:
        e = cl.index(0, q); name = cl[q:e].decode(); q = e + 1
        (t,) = struct.unpack_from("<i", cl, q); q += 16
        chans.append((name, 2 if t == 1 else 4))
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    comp = attrs["compression"][1][0]
    lines = {0: 1, 2: 1, 3: 16}.get(comp)
    assert lines, f"{path}: compression {comp} not supported here"
    offsets = struct.unpack_from(f"<{(h + lines - 1) // lines}Q", b, p)
    row = w * sum(s for _, s in chans)
    chunks = []
    for off in offsets:
        y, size = struct.unpack_from("<ii", b, off)
        data, n = b[off + 8:off + 8 + size], min(lines, y1 + 1 - y)
        if size < n * row:  # compressed (a chunk that would not shrink is stored raw)
            t = bytearray(zlib.decompress(data))
            for i in range(1, len(t)):
                t[i] = (t[i - 1] + t[i] - 128) & 0xFF
            half, data = (len(t) + 1) // 2, bytearray(len(t))
            data[0::2], data[1::2] = t[:half], t[half:]
        assert len(data) == n * row, f"{path}: chunk at line {y} has {len(data)} bytes, expected {n * row}"
        chunks.append((y, bytes(data), n))
    planes = {name: bytearray() for name, _ in chans}
    for y, data, n in sorted(chunks):
        o = 0
        for _ in range(n):
            for name, s in chans:
                planes[name] += data[o:o + s * w]; o += s * w
    text = {k: v.decode("utf-8", "replace") for k, (t, v) in attrs.items() if t == "string"}
    return w, h, {k: bytes(v) for k, v in planes.items()}, text

def exrcmp(a, b, spp, parts):
    """Exit 0 iff a and b have the same size, channels and pixel bits (and are not black);
    b's strata.spp must be spp and its strata.part_count parts."""
    wa, ha, pa, ta = exr(a)
    wb, hb, pb, tb = exr(b)
    ok = True
    if (wa, ha) != (wb, hb) or sorted(pa) != sorted(pb):
        print(f"differ in size or channels: {wa}x{ha} {sorted(pa)} vs {wb}x{hb} {sorted(pb)}"); ok = False
    else:
        for c in sorted(pa):
            if pa[c] != pb[c]:
                va, vb = pa[c], pb[c]
                bad = sum(va[i:i + 4] != vb[i:i + 4] for i in range(0, len(va), 4))
                print(f"channel {c}: {bad} of {wa * ha} pixels differ"); ok = False
    r = struct.unpack(f"<{wa * ha}f", pa.get("R", b"")) if "R" in pa else ()
    if not any(r):
        print("R is black: proves nothing"); ok = False
    for k, want in (("strata.spp", spp), ("strata.part_count", parts)):
        if tb.get(k) != want:
            print(f"{b}: {k} = {tb.get(k)}, expected {want}"); ok = False
    if ok:
        print(f"same pixels: {wa}x{ha}, channels {','.join(sorted(pa))}, strata.spp {tb.get('strata.spp')}")
    sys.exit(0 if ok else 1)

if __name__ == "__main__":
    {"ckpt": ckpt, "exrcmp": exrcmp}[sys.argv[1]](*sys.argv[2:])
PY
tool() { python3 "$tmp/tool.py" "$@"; }

# ---- 2. munge and Slurm ----------------------------------------------------------------------
host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$tmp"/{munge,state,spool,run,log,work}
chown munge:munge "$tmp/munge"
chmod 700 "$tmp/munge"
setpriv --reuid=munge --regid=munge --init-groups mungekey -c -k "$tmp/munge/munge.key"
chmod 711 "$tmp/munge"  # root's clients and daemons reach the socket; munge owns the rest
setpriv --reuid=munge --regid=munge --init-groups munged -F --socket="$tmp/munge/munge.socket" \
  --key-file="$tmp/munge/munge.key" --pid-file="$tmp/munge/munged.pid" --seed-file="$tmp/munge/munged.seed" \
  --log-file="$tmp/munge/munged.log" >"$tmp/log/munged.out" 2>&1 &
munged_pid=$!
wait_for "munged's socket" 15 test -S "$tmp/munge/munge.socket"

read -r ctld_port slurmd_port < <(python3 -c '
import socket
ss = [socket.socket() for _ in range(2)]
for s in ss: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in ss])')
export SLURM_CONF="$tmp/slurm.conf"
cat >"$SLURM_CONF" <<EOF
# Generated by scripts/test-slurm.sh: a private one-node cluster in $tmp.
ClusterName=stratatest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# cred_expire is also how long a requeued job waits before it may start again (default 120 s)
AuthInfo=socket=$tmp/munge/munge.socket,cred_expire=10
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/run/slurmctld.pid
SlurmdPidFile=$tmp/run/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=1,bf_interval=1
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
KillWait=30
MinJobAge=3600
MailProg=/bin/true
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=strata Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i -f "$SLURM_CONF" >"$tmp/log/slurmctld.out" 2>&1 &
ctld_pid=$!
wait_for "slurmctld (scontrol ping)" 30 bash -c 'scontrol ping 2>/dev/null | grep -q UP'
slurmd -D -f "$SLURM_CONF" >"$tmp/log/slurmd.out" 2>&1 &
slurmd_pid=$!
node_idle() { sinfo -h -n "$host" -o %T 2>/dev/null | grep -qx idle; }
wait_for "node $host idle (sinfo)" 30 node_idle
say "slurm up on $host ($cpus CPUs, ports $ctld_port/$slurmd_port) after $(( SECONDS - started )) s"

# ---- 3. submit, and the one-machine render alongside -----------------------------------------
work="$tmp/work"
cd "$work"
# Mixed CPUs: every array task pins Embree to isa=avx2, the recipe for a cluster with AVX2-only nodes.
cat >"$tmp/strata-mixed-isa" <<EOF
#!/bin/sh
export STRATA_EMBREE_CONFIG=isa=avx2
exec "$STRATA" "\$@"
EOF
chmod 755 "$tmp/strata-mixed-isa"
submitted=$(SCENE="$SCENE" SPP=$SPP SHARDS=$SHARDS CPUS=1 OUT="$work/ref" FLAGS="$FLAGS" STRATA="$tmp/strata-mixed-isa" \
  CHECKPOINT_EVERY=0 QUIET=0 "$root/examples/cluster/slurm-submit.sh")
say "$submitted"
read -r array merge < <(sed -E 's/^submitted array ([0-9]+) .* merge ([0-9]+) .*/\1 \2/' <<<"$submitted")
[[ "$array" =~ ^[0-9]+$ && "$merge" =~ ^[0-9]+$ ]] || die "cannot parse job ids from: $submitted"
# shellcheck disable=SC2086 # FLAGS is a list of flags
STRATA_EMBREE_CONFIG=isa=avx2 "$STRATA" render "$SCENE" --spp "$SPP" $FLAGS -o "$work/whole" -q 2>"$tmp/log/whole.log" &
ref_pid=$!

job_field() { # job_field JOB FIELD: FIELD=value of `scontrol show job -o JOB` (first record)
  scontrol show job -o "$1" 2>/dev/null | head -n1 | tr ' ' '\n' | sed -n "s/^$2=//p"
}
# ---- 4. requeue one task mid-render ----------------------------------------------------------
task="${array}_$REQ" ck="$work/ref.parts/part-$REQ.ckpt" log="$work/ref.parts/slurm-${task}.log"
a=$(( REQ * SPP / SHARDS )) b=$(( (REQ + 1) * SPP / SHARDS ))
running_with_ckpt() { [ "$(job_field "$task" JobState)" = RUNNING ] && [ -f "$ck" ]; }
wait_for "task $task running with a first checkpoint" 120 running_with_ckpt
read -r _ held _ _ < <(tool ckpt "$ck")
[ "$held" -lt "$b" ] || die "task $task finished its range before the requeue; raise SLURM_TEST_SPP"
scontrol requeue "$task"
say "requeued $task (samples $a..$b) while running, its checkpoint holding $a..$held"
# RUNNING -> COMPLETING (strata finishes its pass, checkpoints, exits) -> PENDING (BeginTime)
requeued() { [ "$(job_field "$task" JobState)" = PENDING ]; }
wait_for "task $task to stop and be pending again after the requeue" 60 requeued
read -r _ m _ _ < <(tool ckpt "$ck")
say "task $task is $(job_field "$task" JobState) ($(job_field "$task" Reason)); checkpoint holds $a..$m"
if [ "$m" -le "$a" ] || [ "$m" -ge "$b" ]; then die "checkpoint of $task holds $a..$m: not a part of $a..$b"; fi

# ---- 5. wait for everything, then check -------------------------------------------------------
merge_done() {
  local s; s=$(job_field "$merge" JobState)
  case "$s" in
    COMPLETED) return 0 ;;
    PENDING|RUNNING|CONFIGURING|COMPLETING|REQUEUED|"") return 1 ;;
    *) die "merge job $merge is $s ($(job_field "$merge" Reason))" ;;
  esac
}
wait_for "merge job $merge" "$(left)" merge_done
wait "$ref_pid" || die "the one-machine render failed: $(cat "$tmp/log/whole.log")"
ref_pid=
say "merge job done after $(( SECONDS - started )) s"

for i in $(seq 0 $(( SHARDS - 1 ))); do
  s=$(job_field "${array}_$i" JobState) r=$(job_field "${array}_$i" Restarts) x=$(job_field "${array}_$i" ExitCode)
  if [ "$s" != COMPLETED ] || [ "$x" != 0:0 ]; then die "task ${array}_$i is $s, exit $x"; fi
  if [ "$i" = "$REQ" ]; then want=1; else want=0; fi
  [ "$r" = "$want" ] || die "task ${array}_$i restarted $r times, expected $want"
done
grep -q "restart 1," "$log" || die "$log: no second run (restart 1)"
grep -q "task $REQ resumes from $ck" "$log" || die "$log: the second run did not resume from $ck"
k=$(sed -n 's/^strata: interrupted after \([0-9]*\) spp.*/\1/p' "$log")
[ "$k" = $(( m - a )) ] || die "$log: strata did not stop on SIGTERM after $(( m - a )) spp (said: '${k}')"
# The second run's summary counts its camera rays: one per pixel and sample it rendered.
cams=$(sed -n 's/.*(camera \([0-9]*\),.*/\1/p' "$log")
px=$(( ${SIZE%x*} * ${SIZE#*x} ))
if [ "$cams" != $(( px * (b - m) )) ]; then  # exactly one summary line: the second run's
  die "$log: the second run traced camera rays '$cams', expected $(( px * (b - m) )) = ${SIZE} x $(( b - m )) samples"
fi
say "requeue verified: Restarts=1; SIGTERM stopped strata after $k spp with checkpoint $a..$m; the rerun resumed it and rendered $m..$b only"

cmp "$work/whole.png" "$work/ref.png" || die "merged PNG differs from the one-machine render"
tool exrcmp "$work/whole.exr" "$work/ref.exr" "$SPP" "$SHARDS" >"$tmp/exrcmp.txt" || { cat "$tmp/exrcmp.txt" >&2; die "merged EXR differs"; }
say "merged = one-machine render: PNG bytes equal; EXR $(cat "$tmp/exrcmp.txt")"
say "every task and the one-machine render ran with STRATA_EMBREE_CONFIG=isa=avx2 (a mixed cluster's pin): bit-identical"

# ---- 6. a part rendered unpinned (AVX-512) does not merge -----------------------------------------
ia=$(( ISA_TASK * SPP / SHARDS )) ib=$(( (ISA_TASK + 1) * SPP / SHARDS ))
if grep -qw avx512bw /proc/cpuinfo; then
  # shellcheck disable=SC2086 # FLAGS is a list of flags
  env -u STRATA_EMBREE_CONFIG "$STRATA" render "$SCENE" --spp "$SPP" $FLAGS --samples "$ia..$ib" \
    -o "$work/avx512-part" -q 2>"$tmp/log/avx512.log" || die "the isa=avx512 part failed: $(cat "$tmp/log/avx512.log")"
  others=()
  for i in $(seq 0 $(( SHARDS - 1 ))); do [ "$i" = "$ISA_TASK" ] || others+=("$work/ref.parts/part-$i.ckpt"); done
  if "$STRATA" merge "${others[@]}" "$work/avx512-part.ckpt" -o "$work/mixed" -q 2>"$tmp/mixed.txt"; then
    die "a part rendered unpinned (avx512) merged with avx2 parts"
  fi
  grep -q 'embree_isa "avx512"' "$tmp/mixed.txt" && grep -q '"avx2")' "$tmp/mixed.txt" \
    || die "the refusal does not name both instruction sets: $(cat "$tmp/mixed.txt")"
  [ ! -e "$work/mixed.exr" ] || die "a refused merge wrote $work/mixed.exr"
  say "a part of samples $ia..$ib rendered unpinned (avx512) is refused: $(cat "$tmp/mixed.txt")"
else
  say "no AVX-512 on this CPU: the default is avx2 here, so the unpinned part is not rendered"
fi
passed=1

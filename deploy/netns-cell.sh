#!/usr/bin/env bash
# A multi-host tandem cell on one machine: every [[hosts]] entry of the cell file becomes a
# network namespace with its own address, joined by veth links to a bridge in a hub namespace,
# and runs `tandem up <cell> --host <host> --epoch-ns <shared epoch> --no-view` in it.
#
#   sudo deploy/netns-cell.sh up [options]      create the namespaces, start every host
#   sudo deploy/netns-cell.sh status            which hosts run, their processes, tandem status
#   sudo deploy/netns-cell.sh down              stop every host, delete the namespaces
#
# See deploy/README.md ("A multi-host cell on one machine").
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CELL="$ROOT/config/press.toml"
BIN="${TANDEM_BIN:-$ROOT/target/release}"
STATE=""
SCRIPT=""
RECORD=0
AHEAD=5
HUB_SUFFIX="hub"

usage() {
    cat <<EOF
usage: $(basename "$0") up     [--cell FILE] [--script FILE] [--record] [--ahead S] [--dir DIR]
       $(basename "$0") status [--cell FILE] [--dir DIR]
       $(basename "$0") down   [--cell FILE] [--dir DIR]

Builds a multi-host cell on this machine with network namespaces: one namespace per [[hosts]]
entry of the cell file (named like the host), its address taken from the host's first
\`listen\` endpoint (/24), each on a veth link to a bridge in the namespace <cell>$HUB_SUFFIX.
In each it starts
    tandem up <cell> --host <host> --epoch-ns <epoch> --no-view
with one epoch for all hosts, --ahead seconds from now (default $AHEAD: time for the gateways
to connect). Logs and pids go to --dir (default /tmp/tandem-netns-<cell>), printed by \`up\`.

  --cell FILE     the cell (default config/press.toml)
  --script FILE   pass --script to every host (the cell stops when the script ends)
  --record        pass --record <dir>/<host> to every host (each node's CSV trace and log)
  --ahead S       the shared epoch is this many whole seconds ahead (default $AHEAD)
  --dir DIR       where logs, pids and the epoch are kept

Needs root (ip netns). Uses the binaries in \$TANDEM_BIN (default target/release): tandem,
tandem-node, tandem-gateway. Build them with
    cargo build --release --bins
EOF
}

die() {
    echo "netns-cell: error: $*" >&2
    exit 1
}

[[ $# -ge 1 ]] || { usage >&2; exit 2; }
CMD="$1"
shift
case "$CMD" in
    up | status | down) ;;
    -h | --help | help) usage; exit 0 ;;
    *) echo "netns-cell: unknown command \`$CMD\`" >&2; usage >&2; exit 2 ;;
esac
while [[ $# -gt 0 ]]; do
    case "$1" in
        --cell) CELL="${2:?--cell needs a file}"; shift 2 ;;
        --script) SCRIPT="${2:?--script needs a file}"; shift 2 ;;
        --record) RECORD=1; shift ;;
        --ahead) AHEAD="${2:?--ahead needs seconds}"; shift 2 ;;
        --dir) STATE="${2:?--dir needs a directory}"; shift 2 ;;
        -h | --help) usage; exit 0 ;;
        *) echo "netns-cell: unknown option \`$1\`" >&2; usage >&2; exit 2 ;;
    esac
done

if [[ $EUID -ne 0 ]]; then
    die "this needs root: it creates network namespaces and veth links (ip netns add, ip link add).
Run it as root, e.g. sudo $0 $CMD"
fi
command -v ip >/dev/null || die "\`ip\` not found (Debian/Ubuntu package iproute2)"
[[ -f "$CELL" ]] || die "$CELL: no such cell file"
CELL="$(realpath "$CELL")"
[[ "$AHEAD" =~ ^[0-9]+$ ]] || die "--ahead takes whole seconds, not \`$AHEAD\`"

# The cell's name and its hosts with their first listen address, from the cell file.
CELL_NAME="$(awk '
    /^\[/ { sec = $0 }
    sec == "[cell]" && /^[ \t]*name[ \t]*=/ { if (match($0, /"[^"]*"/)) { print substr($0, RSTART + 1, RLENGTH - 2); exit } }
' "$CELL")"
[[ -n "$CELL_NAME" ]] || die "$CELL: no [cell] name"
mapfile -t HOSTLINES < <(awk '
    /^\[/ { if (name != "") print name, addr; name = ""; addr = ""; inhost = ($0 ~ /^\[\[hosts\]\]/) }
    inhost && /^[ \t]*name[ \t]*=/ { if (match($0, /"[^"]*"/)) name = substr($0, RSTART + 1, RLENGTH - 2) }
    inhost && /^[ \t]*listen[ \t]*=/ { if (match($0, /[0-9]+\.[0-9]+\.[0-9]+\.[0-9]+/)) addr = substr($0, RSTART, RLENGTH) }
    END { if (name != "") print name, addr }
' "$CELL")
[[ ${#HOSTLINES[@]} -ge 2 ]] || die "$CELL: needs at least two [[hosts]] (it has ${#HOSTLINES[@]})"
HOSTS=()
ADDRS=()
for l in "${HOSTLINES[@]}"; do
    h="${l%% *}"
    a="${l#* }"
    [[ "$a" != "$h" && -n "$a" ]] ||
        die "$CELL: host \`$h\` has no listen = [\"tcp/<IPv4>:<port>\"]; the namespace needs its address"
    HOSTS+=("$h")
    ADDRS+=("$a")
done
HUB="${CELL_NAME}${HUB_SUFFIX}"
STATE="${STATE:-/tmp/tandem-netns-$CELL_NAME}"

ns_exists() { ip netns list | awk '{print $1}' | grep -qx -- "$1"; }

# The pid of a host's `tandem up`, if it runs (checked against its command line).
up_pid() {
    local f="$STATE/$1.pid" pid
    [[ -f "$f" ]] || return 1
    pid="$(cat "$f")"
    [[ -n "$pid" && -d "/proc/$pid" ]] || return 1
    tr '\0' ' ' <"/proc/$pid/cmdline" | grep -q -- "--host $1 " || return 1
    echo "$pid"
}

cmd_up() {
    local t
    for t in tandem tandem-node tandem-gateway; do
        [[ -x "$BIN/$t" ]] || die "$BIN/$t is missing: build the binaries first:
    cd $ROOT && cargo build --release --bins
(or set TANDEM_BIN to the directory of installed ones)"
    done
    for h in "${HOSTS[@]}" "$HUB"; do
        ! ns_exists "$h" || die "namespace \`$h\` exists already: is the cell up? ($0 status, $0 down)"
    done
    if [[ -n "$SCRIPT" ]]; then
        [[ -f "$SCRIPT" ]] || die "$SCRIPT: no such script"
        SCRIPT="$(realpath "$SCRIPT")"
    fi
    "$BIN/tandem" check "$CELL" >/dev/null || die "$CELL does not pass tandem check"
    mkdir -p "$STATE"
    rm -f "$STATE"/*.pid "$STATE"/*.log

    echo "netns-cell: namespaces ${HOSTS[*]} on a bridge in $HUB"
    ip netns add "$HUB"
    ip -n "$HUB" link add br0 type bridge
    ip -n "$HUB" link set br0 up
    ip -n "$HUB" link set lo up
    local i
    for i in "${!HOSTS[@]}"; do
        h="${HOSTS[$i]}"
        ip netns add "$h"
        ip link add eth0 netns "$h" type veth peer name "h$i" netns "$HUB"
        ip -n "$HUB" link set "h$i" master br0
        ip -n "$HUB" link set "h$i" up
        ip -n "$h" addr add "${ADDRS[$i]}/24" dev eth0
        ip -n "$h" link set eth0 up
        ip -n "$h" link set lo up
        echo "  $h  ${ADDRS[$i]}/24"
    done

    # One epoch for every host: cycle 0 of every node is at this CLOCK_REALTIME instant.
    local epoch=$((($(date +%s) + AHEAD) * 1000000000))
    echo "$epoch" >"$STATE/epoch"
    for h in "${HOSTS[@]}"; do
        local args=(up "$CELL" --host "$h" --epoch-ns "$epoch" --no-view)
        if [[ -n "$SCRIPT" ]]; then args+=(--script "$SCRIPT"); fi
        if [[ $RECORD -eq 1 ]]; then args+=(--record "$STATE/$h"); fi
        # The shell writes its pid and becomes `ip netns exec`, which becomes `tandem up`: the
        # pid in the file is tandem up's. setsid: not tied to this terminal.
        # shellcheck disable=SC2016
        setsid bash -c 'echo $$ >"$1"; shift; exec "$@"' _ "$STATE/$h.pid" \
            ip netns exec "$h" "$BIN/tandem" "${args[@]}" \
            </dev/null >"$STATE/$h.log" 2>&1 &
    done
    sleep 1
    local failed=0
    for h in "${HOSTS[@]}"; do
        if pid="$(up_pid "$h")"; then
            echo "  $h: tandem up pid $pid, log $STATE/$h.log"
        else
            echo "  $h: tandem up did not start; log $STATE/$h.log:" >&2
            sed 's/^/    /' "$STATE/$h.log" >&2 || true
            failed=1
        fi
    done
    echo "netns-cell: epoch $epoch ($(date -d "@$((epoch / 1000000000))" '+%F %T %Z')); logs in $STATE"
    if [[ $failed -eq 1 ]]; then
        echo "netns-cell: a host did not start; stopping the others" >&2
        cmd_down
        exit 1
    fi
    echo "Observe a host:  ip netns exec ${HOSTS[0]} $BIN/tandem status --cell $CELL --host ${HOSTS[0]}"
    echo "Stop the cell:   $0 down${STATE:+ --dir $STATE}"
}

cmd_status() {
    local running=0
    if [[ -f "$STATE/epoch" ]]; then echo "epoch $(cat "$STATE/epoch"), logs in $STATE"; fi
    for h in "${HOSTS[@]}"; do
        if ! ns_exists "$h"; then
            echo "$h: no namespace"
            continue
        fi
        if pid="$(up_pid "$h")"; then
            running=$((running + 1))
            echo "$h: running (tandem up pid $pid)"
        else
            echo "$h: namespace exists, tandem up not running"
        fi
        local pids
        pids="$(ip netns pids "$h" | paste -sd, -)"
        if [[ -n "$pids" ]]; then
            ps -o pid=,etime=,args= -p "$pids" | sed 's/^/    /'
        fi
    done
    for h in "${HOSTS[@]}"; do
        up_pid "$h" >/dev/null || continue
        echo
        echo "== tandem status --host $h"
        ip netns exec "$h" "$BIN/tandem" status --cell "$CELL" --host "$h" || true
    done
    # Exit 0 when every host runs, 3 otherwise (as tandem status).
    if [[ $running -ne ${#HOSTS[@]} ]]; then exit 3; fi
}

# SIGTERM to `tandem up` (it stops its nodes and gateway: SIGTERM, SIGKILL after 5 s), then
# whatever still runs in the namespace, then the namespaces.
cmd_down() {
    local h pid
    for h in "${HOSTS[@]}"; do
        if pid="$(up_pid "$h")"; then
            echo "netns-cell: stopping $h (tandem up pid $pid)"
            kill -TERM "$pid" 2>/dev/null || true
        fi
    done
    local deadline=$((SECONDS + 10))
    for h in "${HOSTS[@]}"; do
        while up_pid "$h" >/dev/null && [[ $SECONDS -lt $deadline ]]; do sleep 0.2; done
    done
    for h in "${HOSTS[@]}" "$HUB"; do
        ns_exists "$h" || continue
        local left
        left="$(ip netns pids "$h" | tr '\n' ' ')"
        if [[ -n "${left// /}" ]]; then
            echo "netns-cell: $h: still running, SIGTERM then SIGKILL: $left" >&2
            # shellcheck disable=SC2086
            kill -TERM $left 2>/dev/null || true
            sleep 2
            left="$(ip netns pids "$h" | tr '\n' ' ')"
            # shellcheck disable=SC2086
            [[ -z "${left// /}" ]] || kill -KILL $left 2>/dev/null || true
            sleep 0.2
        fi
        ip netns del "$h"
        echo "netns-cell: deleted namespace $h"
    done
    rm -f "$STATE"/*.pid
    for h in "${HOSTS[@]}"; do
        if [[ -f "$STATE/$h.log" ]]; then echo "  $h: $(tail -n 1 "$STATE/$h.log")"; fi
    done
    echo "netns-cell: down; logs kept in $STATE"
}

"cmd_$CMD"

#!/bin/sh
# Install rangebearing as a systemd service on Raspberry Pi OS (Bookworm or Bullseye).
#
#   sudo systemd/install.sh             install or upgrade, then (re)start the service
#   systemd/install.sh --dry-run        print every step, change nothing (no root needed)
#   sudo systemd/install.sh --no-start  install and enable, but do not (re)start now
#
# Safe to run again: apt and venv creation are idempotent, the package is
# reinstalled from this checkout, the user is created only if missing, and an
# existing /etc/rangebearing/config.yaml is never overwritten.
# See docs/raspberry-pi.md for what each step does and the manual equivalent.

set -eu

PREFIX=/opt/rangebearing
VENV=$PREFIX/venv
ETC_DIR=/etc/rangebearing
CONFIG=$ETC_DIR/config.yaml
UNIT_DIR=/etc/systemd/system
UNIT=rangebearing.service
SERVICE_USER=rangebearing
APT_PACKAGES="python3-picamera2 python3-opencv python3-numpy python3-yaml python3-tqdm python3-venv"

# The checkout this script lives in (systemd/..).
SRC_DIR=$(CDPATH='' cd -- "$(dirname -- "$0")/.." && pwd)

DRY_RUN=0
START=1

usage() {
    sed -n '2,11s/^# \{0,1\}//p' "$0"
}

say() {
    printf '==> %s\n' "$*"
}

die() {
    printf 'install.sh: error: %s\n' "$*" >&2
    exit 1
}

# The command line as a shell would read it back (arguments with spaces quoted).
quoted() {
    out=
    for a in "$@"; do
        case $a in
            '' | *[!A-Za-z0-9_./:=@%+,-]*) a="'$(printf '%s' "$a" | sed "s/'/'\\\\''/g")'" ;;
        esac
        out="$out${out:+ }$a"
    done
    printf '%s' "$out"
}

# Print a command, then run it unless --dry-run.
run() {
    if [ "$DRY_RUN" -eq 1 ]; then
        printf '[dry-run] %s\n' "$(quoted "$@")"
    else
        printf '+ %s\n' "$(quoted "$@")"
        "$@"
    fi
}

for arg in "$@"; do
    case $arg in
        --dry-run|-n) DRY_RUN=1 ;;
        --no-start) START=0 ;;
        -h|--help) usage; exit 0 ;;
        *) die "unknown option '$arg' (try --help)" ;;
    esac
done

if [ "$DRY_RUN" -eq 0 ] && [ "$(id -u)" -ne 0 ]; then
    die "must be run as root (try: sudo $0), or use --dry-run to see the steps"
fi

[ -f "$SRC_DIR/pyproject.toml" ] || die "no pyproject.toml in $SRC_DIR; run the script from a rangebearing checkout"
[ -f "$SRC_DIR/systemd/$UNIT" ] || die "missing $SRC_DIR/systemd/$UNIT"
if [ ! -f "$SRC_DIR/config/rangebearing.yaml" ]; then
    if [ "$DRY_RUN" -eq 1 ]; then
        say "warning: $SRC_DIR/config/rangebearing.yaml is missing; a real run would stop here"
    else
        die "missing $SRC_DIR/config/rangebearing.yaml (the default config)"
    fi
fi

say "1/7 system packages (numpy, OpenCV and picamera2 come from apt, built for the Pi)"
run apt-get update
run env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $APT_PACKAGES

say "2/7 virtual environment $VENV that can see apt's packages"
run install -d -m 0755 "$PREFIX"
run python3 -m venv --system-site-packages "$VENV"

say "3/7 rangebearing from $SRC_DIR (--no-deps: never pip-install a second numpy over apt's)"
run "$VENV/bin/pip" install --no-deps --no-cache-dir --upgrade "$SRC_DIR"
run "$VENV/bin/python" -c "import numpy, cv2, yaml, rangebearing"
if [ -f "$SRC_DIR/docs/raspberry-pi.md" ]; then
    run install -D -m 0644 "$SRC_DIR/docs/raspberry-pi.md" "$PREFIX/docs/raspberry-pi.md"
fi

say "4/7 system user $SERVICE_USER in group video"
if getent passwd "$SERVICE_USER" >/dev/null 2>&1; then
    run usermod -a -G video "$SERVICE_USER"
else
    run useradd --system --user-group --groups video --no-create-home \
        --home-dir /nonexistent --shell /usr/sbin/nologin "$SERVICE_USER"
fi

say "5/7 configuration $CONFIG"
run install -d -m 0755 "$ETC_DIR"
if [ -e "$CONFIG" ]; then
    say "keeping the existing $CONFIG (never overwritten; the shipped default is $SRC_DIR/config/rangebearing.yaml)"
else
    run install -m 0644 "$SRC_DIR/config/rangebearing.yaml" "$CONFIG"
fi
# The daemon may write nowhere; its start-up reads what this check leaves here (the parsed config, the
# dataclasses' compiled methods: docs/daemon-cost.md). Edited the config later? Run this line again.
run install -d -m 0755 "$PREFIX/cache"
run env RANGEBEARING_CACHE="$PREFIX/cache" "$VENV/bin/rangebearing" run --check --config "$CONFIG" \
    || say "warning: $CONFIG does not pass 'rangebearing run --check' (see above); the daemon will say so too"

say "6/7 unit $UNIT_DIR/$UNIT"
run install -m 0644 "$SRC_DIR/systemd/$UNIT" "$UNIT_DIR/$UNIT"
run systemctl daemon-reload

say "7/7 enable at boot and (re)start"
run systemctl enable "$UNIT"
if [ "$START" -eq 1 ]; then
    run systemctl restart "$UNIT"
fi
if [ "$DRY_RUN" -eq 1 ]; then
    say "dry run: nothing was changed"
elif [ "$START" -eq 1 ]; then
    say "done: follow the log with: journalctl -u rangebearing -f"
else
    say "done: start it with: systemctl start rangebearing"
fi

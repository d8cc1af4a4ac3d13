#!/usr/bin/env bash
# Installs gaitd as a systemd service (idempotent). Run from a checkout:
#   cargo build --release && sudo deploy/install.sh
# Options: --bin-dir DIR (default /usr/local/bin), --no-start.
set -euo pipefail
cd "$(dirname "$0")/.."

BIN_DIR=/usr/local/bin
START=1
while [ $# -gt 0 ]; do
  case "$1" in
    --bin-dir) BIN_DIR="$2"; shift 2 ;;
    --no-start) START=0; shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done

[ "$(id -u)" -eq 0 ] || { echo "run as root (sudo $0)" >&2; exit 1; }
for b in gaitd gaitctl; do
  [ -x "target/release/$b" ] || { echo "target/release/$b missing: cargo build --release" >&2; exit 1; }
done

# A dedicated system user; clients run as this user too (iceoryx2 resources are owner-only).
if ! id gaitd >/dev/null 2>&1; then
  useradd --system --no-create-home --home-dir /nonexistent --shell /usr/sbin/nologin gaitd
fi

install -d -m 0755 "$BIN_DIR" /etc/gaitd /usr/local/share/doc/gaitd
install -m 0755 target/release/gaitd target/release/gaitctl "$BIN_DIR/"
# Keep an edited config; ship the example next to it.
if [ -e /etc/gaitd/gaitd.toml ]; then
  install -m 0644 deploy/gaitd.toml /etc/gaitd/gaitd.toml.example
else
  install -m 0644 deploy/gaitd.toml /etc/gaitd/gaitd.toml
fi
install -m 0644 deploy/iceoryx2.toml /etc/gaitd/iceoryx2.toml
install -m 0644 deploy/RT-TUNING.md /usr/local/share/doc/gaitd/RT-TUNING.md
sed "s|/usr/local/bin/gaitd|$BIN_DIR/gaitd|" deploy/gaitd.service >/etc/systemd/system/gaitd.service

# gaitd-bridge (remote clients over Zenoh), when built: installed, not
# started. It needs certificates first (README, "Remote clients"), then
#   systemctl enable --now gaitd-bridge.service
if [ -x target/release/gaitd-bridge ]; then
  install -m 0755 target/release/gaitd-bridge "$BIN_DIR/"
  install -m 0644 README.md /usr/local/share/doc/gaitd/README.md
  if [ -e /etc/gaitd/gaitd-bridge.toml ]; then
    install -m 0644 deploy/gaitd-bridge.toml /etc/gaitd/gaitd-bridge.toml.example
  else
    install -m 0644 deploy/gaitd-bridge.toml /etc/gaitd/gaitd-bridge.toml
  fi
  install -d -m 0750 -o gaitd -g gaitd /etc/gaitd/pki
  install -m 0755 deploy/gaitd-certs.sh "$BIN_DIR/gaitd-certs"
  sed "s|/usr/local/bin/gaitd-bridge|$BIN_DIR/gaitd-bridge|g" deploy/gaitd-bridge.service \
    >/etc/systemd/system/gaitd-bridge.service
fi

GAITD_IPC_CONFIG=/etc/gaitd/iceoryx2.toml "$BIN_DIR/gaitd" --config /etc/gaitd/gaitd.toml --check-config >/dev/null
systemctl daemon-reload
if [ "$START" -eq 1 ]; then
  systemctl enable --now gaitd.service
  systemctl --no-pager status gaitd.service || true
fi
cat <<MSG
gaitd installed. Talk to it as the gaitd user:
  sudo -u gaitd GAITD_IPC_CONFIG=/etc/gaitd/iceoryx2.toml $BIN_DIR/gaitctl status
MSG

#!/usr/bin/env bash
# A private CA and the certificates of gaitd-bridge's mutual TLS (openssl).
#
#   gaitd-certs.sh [--dir DIR] [--days N] ca
#       the CA: DIR/ca.pem (give it to the bridge and every client) and
#       DIR/ca.key (signs everything: keep it offline, never on a robot)
#   gaitd-certs.sh [--dir DIR] [--days N] bridge [HOST...]
#       the bridge's certificate DIR/bridge.pem, DIR/bridge.key, valid for
#       localhost, 127.0.0.1, ::1 and each HOST (names or addresses that
#       clients put in quic/HOST:PORT or tls/HOST:PORT)
#   gaitd-certs.sh [--dir DIR] [--days N] client NAME
#       a client certificate DIR/NAME.pem, DIR/NAME.key with common name
#       NAME: the identity the bridge's [[identity]] entries name (operator
#       or monitor). Give the client ca.pem, NAME.pem and NAME.key.
#
# DIR defaults to ./pki, N to 825 days. Keys are EC P-256, mode 0600.
# Revoking a client: remove its [[identity]] entry (the bridge then denies
# it everything) and restart the bridge.
set -euo pipefail

dir=./pki
days=825
while [ $# -gt 0 ]; do
  case "$1" in
    --dir) dir="$2"; shift 2 ;;
    --days) days="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) break ;;
  esac
done
[ $# -ge 1 ] || { echo "usage: $0 [--dir DIR] [--days N] ca | bridge [HOST...] | client NAME" >&2; exit 2; }
command -v openssl >/dev/null || { echo "openssl not found (apt-get install openssl)" >&2; exit 1; }
what="$1"; shift
mkdir -p "$dir"
umask 077
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

newkey() { openssl ecparam -name prime256v1 -genkey -noout -out "$1" 2>/dev/null && chmod 600 "$1"; }

need_ca() {
  [ -f "$dir/ca.pem" ] && [ -f "$dir/ca.key" ] \
    || { echo "no CA in $dir: run '$0 --dir $dir ca' first" >&2; exit 1; }
}

# sign NAME CN EXTFILE: DIR/NAME.key + DIR/NAME.pem signed by the CA.
sign() {
  local name="$1" cn="$2" ext="$3"
  newkey "$dir/$name.key"
  openssl req -new -key "$dir/$name.key" -subj "/CN=$cn" -out "$tmp/$name.csr"
  openssl x509 -req -in "$tmp/$name.csr" -CA "$dir/ca.pem" -CAkey "$dir/ca.key" \
    -CAcreateserial -CAserial "$tmp/ca.srl" -days "$days" -sha256 \
    -extfile "$ext" -out "$dir/$name.pem" 2>/dev/null
  chmod 644 "$dir/$name.pem"
  echo "$dir/$name.pem (CN=$cn), key $dir/$name.key"
}

case "$what" in
  ca)
    [ ! -e "$dir/ca.key" ] || { echo "$dir/ca.key exists: not overwriting a CA" >&2; exit 1; }
    newkey "$dir/ca.key"
    openssl req -new -x509 -key "$dir/ca.key" -subj "/CN=gaitd private CA" -days "$days" -sha256 \
      -addext "basicConstraints=critical,CA:TRUE,pathlen:0" \
      -addext "keyUsage=critical,keyCertSign,cRLSign" \
      -addext "subjectKeyIdentifier=hash" \
      -out "$dir/ca.pem"
    chmod 644 "$dir/ca.pem"
    echo "$dir/ca.pem (CA), key $dir/ca.key: keep the key offline"
    ;;
  bridge)
    need_ca
    san="DNS:localhost,IP:127.0.0.1,IP:::1"
    for h in "$@"; do
      if [[ "$h" =~ ^[0-9.]+$ || "$h" == *:* ]]; then san="$san,IP:$h"; else san="$san,DNS:$h"; fi
    done
    cat >"$tmp/ext" <<EXT
basicConstraints=critical,CA:FALSE
keyUsage=critical,digitalSignature
extendedKeyUsage=serverAuth
subjectAltName=$san
subjectKeyIdentifier=hash
authorityKeyIdentifier=keyid
EXT
    sign bridge gaitd-bridge "$tmp/ext"
    ;;
  client)
    need_ca
    [ $# -eq 1 ] || { echo "usage: $0 client NAME" >&2; exit 2; }
    name="$1"
    [[ "$name" =~ ^[A-Za-z0-9_][A-Za-z0-9._-]{0,63}$ ]] \
      || { echo "NAME must be 1-64 characters of [A-Za-z0-9._-] (it becomes a key chunk)" >&2; exit 2; }
    [ "$name" != ca ] && [ "$name" != bridge ] || { echo "NAME '$name' is reserved" >&2; exit 2; }
    cat >"$tmp/ext" <<EXT
basicConstraints=critical,CA:FALSE
keyUsage=critical,digitalSignature
extendedKeyUsage=clientAuth
subjectKeyIdentifier=hash
authorityKeyIdentifier=keyid
EXT
    sign "$name" "$name" "$tmp/ext"
    ;;
  *)
    echo "unknown command '$what' (ca, bridge, client)" >&2; exit 2 ;;
esac

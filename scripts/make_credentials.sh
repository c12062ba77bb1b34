#!/usr/bin/env bash
# Makes test credentials for navbus under DDS Security (Fast DDS builtin PKI-DH,
# Access-Permissions, AES-GCM-GMAC):
#   OUT/ca/                identity CA and permissions CA (certificates and private keys)
#   OUT/<identity>/        one directory per identity, what `--identity OUT/<identity>` needs:
#       identity_ca.pem    the CA that signs every participant's certificate
#       cert.pem, key.pem  this participant's certificate (CN=navbus-<identity>,O=navbus), key
#       permissions_ca.pem the CA that signs governance and permissions
#       governance.p7s     security/governance.xml, signed (S/MIME)
#       permissions.p7s    security/permissions.xml, signed (S/MIME)
# Identities: the grants of security/permissions.xml (simulator, imu-sensor, filter,
# fault-manager, operator, tool). Keys are ECDSA P-256. These are TEST credentials: the keys
# are made on this machine, are not protected by a passphrase and must never be committed
# (the build makes them under build/security). For a real bus, use your own PKI and edit the
# subject names in security/permissions.xml.
#
# Usage: scripts/make_credentials.sh OUT_DIR [VALID_DAYS]   (default 3650 days)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?usage: make_credentials.sh OUT_DIR [VALID_DAYS]}"
days="${2:-3650}"
policy="$here/security"
identities=$(sed -n 's|.*<subject_name>CN=navbus-\([a-z-]*\),O=navbus</subject_name>.*|\1|p' \
  "$policy/permissions.xml")
[ -n "$identities" ] || { echo "no grant with subject CN=navbus-<name>,O=navbus in $policy/permissions.xml" >&2; exit 2; }

mkdir -p "$out/ca"
chmod 700 "$out/ca"
ca="$out/ca"
ecparam() { openssl ecparam -name prime256v1 -genkey -noout -out "$1" 2> /dev/null; chmod 600 "$1"; }

make_ca() {  # name subject
  ecparam "$ca/$1_key.pem"
  openssl req -new -x509 -sha256 -days "$days" -key "$ca/$1_key.pem" -subj "$2" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign,digitalSignature" \
    -out "$ca/$1.pem"
}
make_ca identity_ca "/O=navbus/CN=navbus identity CA"
make_ca permissions_ca "/O=navbus/CN=navbus permissions CA"

sign() {  # document output
  openssl smime -sign -text -in "$1" -out "$2" -signer "$ca/permissions_ca.pem" \
    -inkey "$ca/permissions_ca_key.pem"
}
sign "$policy/governance.xml" "$ca/governance.p7s"
sign "$policy/permissions.xml" "$ca/permissions.p7s"

for id in $identities; do
  dir="$out/$id"
  mkdir -p "$dir"
  ecparam "$dir/key.pem"
  openssl req -new -sha256 -key "$dir/key.pem" -subj "/O=navbus/CN=navbus-$id" -out "$dir/cert.csr"
  openssl x509 -req -sha256 -days "$days" -in "$dir/cert.csr" -CA "$ca/identity_ca.pem" \
    -CAkey "$ca/identity_ca_key.pem" -CAcreateserial -out "$dir/cert.pem" 2> /dev/null
  rm "$dir/cert.csr"
  cp "$ca/identity_ca.pem" "$dir/identity_ca.pem"
  cp "$ca/permissions_ca.pem" "$dir/permissions_ca.pem"
  cp "$ca/governance.p7s" "$ca/permissions.p7s" "$dir/"
done
echo "credentials for: $(echo $identities) in $out"

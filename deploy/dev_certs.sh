#!/usr/bin/env bash
# A development CA, dispatchd's server certificate, robots' client certificates and bearer
# tokens, for trying TLS, mTLS and roles (issue 18; README "Security"). Not for production:
# the keys are unencrypted and the CA signs anything; a site uses its own PKI and secret store.
#   deploy/dev_certs.sh DIR [ROBOTS]     (ROBOTS: R1..R<ROBOTS> get a certificate and a token; 18)
# Writes into DIR (created; existing files are replaced):
#   ca.crt ca.key              the CA (clients verify the server with ca.crt: --tls-ca)
#   server.crt server.key      dispatchd's certificate (SAN localhost, 127.0.0.1, ::1, dispatchd)
#   robots/R<i>.crt R<i>.key   client certificates, CN and SAN = the robot id (--tls-client-ca ca.crt)
#   tokens.json                dispatchd's token file (--auth-tokens): names, roles, SHA-256 only
#   secrets/wms.token operator.token admin.token   one secret each (--token-file)
#   secrets/robot-tokens.json  {"R1": secret, ...}  (fleet-sim --robot-tokens)
set -euo pipefail
dir=${1:?usage: deploy/dev_certs.sh DIR [ROBOTS]}
robots=${2:-18}
command -v openssl >/dev/null || { echo "dev_certs: openssl is missing (deploy/setup.sh packages)" >&2; exit 1; }
mkdir -p "$dir/robots" "$dir/secrets"
chmod 700 "$dir/secrets"
cd "$dir"
umask 077

key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }
# sign NAME CN SAN: NAME.key + a certificate NAME.crt signed by the CA for CN with SAN.
sign() {
  key "$1.key"
  openssl req -new -key "$1.key" -subj "/CN=$2" -out "$1.csr" 2>/dev/null
  printf 'subjectAltName=%s\nbasicConstraints=CA:FALSE\nkeyUsage=digitalSignature\nextendedKeyUsage=%s\n' \
    "$3" "$4" >"$1.ext"
  openssl x509 -req -in "$1.csr" -CA ca.crt -CAkey ca.key -CAcreateserial -days 825 -sha256 \
    -extfile "$1.ext" -out "$1.crt" 2>/dev/null
  rm -f "$1.csr" "$1.ext"
}

key ca.key
openssl req -x509 -new -key ca.key -subj "/CN=dispatch development CA" -days 3650 -sha256 \
  -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign" -out ca.crt 2>/dev/null
sign server localhost "DNS:localhost,IP:127.0.0.1,IP:::1,DNS:dispatchd" serverAuth

secret() { openssl rand -hex 32; }
sha() { printf %s "$1" | openssl dgst -sha256 -r | cut -d' ' -f1; }
entries=()
for role in wms operator admin; do
  s=$(secret)
  printf '%s\n' "$s" >"secrets/$role.token"
  entries+=("{\"name\": \"$role-dev\", \"role\": \"$role\", \"sha256\": \"$(sha "$s")\"}")
done
robot_secrets=()
for i in $(seq 1 "$robots"); do
  id="R$i"
  sign "robots/$id" "$id" "DNS:$id" clientAuth
  s=$(secret)
  robot_secrets+=("\"$id\": \"$s\"")
  entries+=("{\"name\": \"robot-$id\", \"role\": \"robot\", \"robot_id\": \"$id\", \"sha256\": \"$(sha "$s")\"}")
done
{
  printf '{"tokens": [\n'
  for k in "${!entries[@]}"; do
    printf '  %s%s\n' "${entries[$k]}" "$([ "$k" -lt $((${#entries[@]} - 1)) ] && echo ,)"
  done
  printf ']}\n'
} >tokens.json
(IFS=,; printf '{%s}\n' "${robot_secrets[*]}") >secrets/robot-tokens.json
chmod 644 ca.crt server.crt tokens.json robots/*.crt
echo "dev_certs: CA, server and $robots robot certificates, $((3 + robots)) tokens in $dir"

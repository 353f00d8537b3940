// How the clients (wmsctl, fleet-sim, order-load) reach a dispatchd with TLS and bearer tokens
// (issue 18): one set of flags and the channel credentials and call metadata they give.
//   --tls-ca PEM        verify the server's certificate with this CA (turns TLS on)
//   --tls-cert/--tls-key PEM   a client certificate (mTLS; a robot's names its robot id)
//   --token-file FILE   the bearer token's secret (first line); else $DISPATCH_TOKEN
// Secrets never come from the command line itself (other users can read it in ps).
#pragma once

#include <grpcpp/grpcpp.h>

#include <map>
#include <memory>
#include <string>

namespace CLI {
class App;
}

namespace dispatch::clients {

struct ClientSecurity {
  std::string tls_ca;
  std::string tls_cert;
  std::string tls_key;
  std::string token_file;
  std::string token;  // the secret, once Resolve has read it
};

void AddSecurityOptions(CLI::App& app, ClientSecurity& security);
// Reads the token (token_file, else $DISPATCH_TOKEN) and checks the PEM files are readable.
// False with `error` set when something cannot be read.
bool Resolve(ClientSecurity& security, std::string& error);
// TLS credentials when tls_ca is set, else plaintext.
std::shared_ptr<grpc::ChannelCredentials> Credentials(const ClientSecurity& security);
// Adds `authorization: Bearer <token>` to the call (nothing without a token).
void Authorize(grpc::ClientContext& context, const std::string& token);
// A robot-tokens file (fleet-sim --robot-tokens): a JSON object of robot id -> its token's
// secret. False with `error` set when it cannot be read or is not such an object.
bool ReadRobotTokens(const std::string& path, std::map<std::string, std::string>& out, std::string& error);
// Reads a whole file; false when it cannot be read.
bool ReadWholeFile(const std::string& path, std::string& out);

}  // namespace dispatch::clients

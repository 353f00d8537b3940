#include "clients/client_security.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>
#include <iterator>

namespace dispatch::clients {

void AddSecurityOptions(CLI::App& app, ClientSecurity& security) {
  app.add_option("--tls-ca", security.tls_ca, "Verify the server's TLS certificate with this CA (PEM): use TLS");
  app.add_option("--tls-cert", security.tls_cert, "Client certificate (PEM) for mTLS");
  app.add_option("--tls-key", security.tls_key, "Client certificate's key (PEM)");
  app.add_option("--token-file", security.token_file,
                 "File holding the bearer token (first line); default: $DISPATCH_TOKEN");
}

bool ReadWholeFile(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}

bool Resolve(ClientSecurity& security, std::string& error) {
  if (!security.token_file.empty()) {
    std::string text;
    if (!ReadWholeFile(security.token_file, text)) {
      error = "cannot read the token file '" + security.token_file + "'";
      return false;
    }
    security.token = text.substr(0, text.find_first_of("\r\n"));
    if (security.token.empty()) {
      error = "the token file '" + security.token_file + "' is empty";
      return false;
    }
  } else if (const char* env = std::getenv("DISPATCH_TOKEN"); env && *env) {
    security.token = env;
  }
  if (security.tls_cert.empty() != security.tls_key.empty()) {
    error = "--tls-cert and --tls-key go together";
    return false;
  }
  if (!security.tls_cert.empty() && security.tls_ca.empty()) {
    error = "--tls-cert needs --tls-ca (client certificates come with TLS)";
    return false;
  }
  std::string ignored;
  for (const std::string* path : {&security.tls_ca, &security.tls_cert, &security.tls_key}) {
    if (!path->empty() && !ReadWholeFile(*path, ignored)) {
      error = "cannot read '" + *path + "'";
      return false;
    }
  }
  return true;
}

std::shared_ptr<grpc::ChannelCredentials> Credentials(const ClientSecurity& security) {
  if (security.tls_ca.empty()) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions options;
  ReadWholeFile(security.tls_ca, options.pem_root_certs);
  if (!security.tls_cert.empty()) {
    ReadWholeFile(security.tls_cert, options.pem_cert_chain);
    ReadWholeFile(security.tls_key, options.pem_private_key);
  }
  return grpc::SslCredentials(options);
}

bool ReadRobotTokens(const std::string& path, std::map<std::string, std::string>& out, std::string& error) {
  std::string text;
  if (!ReadWholeFile(path, text)) {
    error = "cannot read '" + path + "'";
    return false;
  }
  try {
    out = nlohmann::json::parse(text).get<std::map<std::string, std::string>>();
  } catch (const nlohmann::json::exception& e) {
    error = "'" + path + "' is not a JSON object of robot ids and secrets: " + e.what();
    return false;
  }
  return true;
}

void Authorize(grpc::ClientContext& context, const std::string& token) {
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
}

}  // namespace dispatch::clients

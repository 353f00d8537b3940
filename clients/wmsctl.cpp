// wmsctl: the warehouse management system's side of the OrderService (SPEC §5).
//   wmsctl --server HOST:PORT submit FILE [--wait]     seed CSV tables or JSON (clients/order_file.h)
//   wmsctl --server HOST:PORT submit --pick "19 17" --pick K2-4-3S --drop "6.5 2.75" [--formation]
//   wmsctl --server HOST:PORT get ID | cancel ID [--reason ..] | explain ID
//   wmsctl --server HOST:PORT list [--state accepted ...]
//   wmsctl --server HOST:PORT watch [--order ID ...] [--after EVENT_ID] [--until-done]
// Exit status: 0 on success, 1 on a usage or connection error, 2 when the server rejected a
// request (its gRPC status and message are printed) or an order ended failed/cancelled
// while waiting.
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "clients/client_security.h"
#include "clients/order_file.h"
#include "clients/order_text.h"
#include "warehouse/dispatch/v1/orders.grpc.pb.h"

namespace dispatch::clients {
namespace {

struct Options {
  std::string server = "127.0.0.1:50051";
  double timeout = 10.0;  // seconds per unary call
  ClientSecurity security;
};

class Client {
 public:
  explicit Client(const Options& options)
      : options_(options),
        stub_(v1::OrderService::NewStub(
            grpc::CreateChannel(options.server, Credentials(options.security)))) {}

  v1::OrderService::Stub& stub() { return *stub_; }
  std::unique_ptr<grpc::ClientContext> Context() const {
    auto ctx = std::make_unique<grpc::ClientContext>();
    ctx->set_deadline(std::chrono::system_clock::now() +
                      std::chrono::milliseconds(static_cast<long>(options_.timeout * 1000)));
    ctx->set_wait_for_ready(true);  // a server still starting is waited for, up to the deadline
    Authorize(*ctx, options_.security.token);
    return ctx;
  }
  const std::string& token() const { return options_.security.token; }

 private:
  Options options_;
  std::unique_ptr<v1::OrderService::Stub> stub_;
};

int Report(const std::string& what, const grpc::Status& status) {
  std::fprintf(stderr, "wmsctl: %s: %s: %s\n", what.c_str(), StatusCodeName(status.error_code()),
               status.error_message().c_str());
  return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
                 status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED
             ? 1
             : 2;
}

// Follows the journal until every order in `ids` is terminal; prints each event when
// `print`. Fills `final_orders`. Returns false when the stream ended first. The watch
// replays each order's journal from its start, so nothing that happened before the call is
// missed.
bool WaitTerminal(Client& client, const std::set<std::string>& ids, bool print,
                  std::map<std::string, v1::Order>* final_orders) {
  grpc::ClientContext ctx;
  Authorize(ctx, client.token());
  v1::WatchOrdersRequest req;
  for (const auto& id : ids) req.add_order_ids(id);
  req.set_from_start(true);
  std::set<std::string> open = ids;
  auto reader = client.stub().WatchOrders(&ctx, req);
  v1::OrderEvent e;
  while (!open.empty() && reader->Read(&e)) {
    if (print) {
      std::printf("%s\n", DescribeEvent(e).c_str());
      std::fflush(stdout);
    }
    if (IsTerminal(e.state()) && open.erase(e.order_id())) {
      v1::GetOrderRequest g;
      g.set_order_id(e.order_id());
      v1::Order o;
      auto c = client.Context();
      if (client.stub().GetOrder(c.get(), g, &o).ok()) (*final_orders)[e.order_id()] = o;
    }
  }
  ctx.TryCancel();
  reader->Finish();
  return open.empty();
}

int Submit(Client& client, std::vector<v1::SubmitOrderRequest> requests, bool wait) {
  int rc = 0;
  std::vector<std::string> ids;
  for (const auto& r : requests) {
    v1::SubmitOrderResponse resp;
    auto ctx = client.Context();
    const grpc::Status s = client.stub().SubmitOrder(ctx.get(), r, &resp);
    if (!s.ok()) {
      rc = std::max(rc, Report("submit " + r.client_order_id(), s));
      continue;
    }
    std::printf("%-24s -> %-10s %-12s %s\n", r.client_order_id().c_str(),
                resp.order().id().c_str(), StateName(resp.order().state()),
                resp.created() ? "created" : "already submitted (same content)");
    ids.push_back(resp.order().id());
  }
  if (!wait || ids.empty()) return rc;
  std::map<std::string, v1::Order> done;
  if (!WaitTerminal(client, {ids.begin(), ids.end()}, false, &done)) {
    std::fprintf(stderr, "wmsctl: the watch stream ended before every order finished\n");
    return 1;
  }
  std::printf("\n%s\n", OrderTableHeader().c_str());
  for (const auto& id : ids) {
    const v1::Order& o = done[id];
    std::printf("%s\n", OrderTableRow(o).c_str());
    if (o.state() != v1::ORDER_STATE_COMPLETED) rc = std::max(rc, 2);
  }
  return rc;
}

int Main(int argc, char** argv) {
  CLI::App app{"wmsctl: submit, follow and cancel warehouse orders"};
  app.require_subcommand(1);
  Options options;
  app.add_option("--server", options.server, "dispatchd gRPC address HOST:PORT")
      ->capture_default_str();
  app.add_option("--timeout", options.timeout, "Seconds per request")->capture_default_str()
      ->check(CLI::PositiveNumber);
  AddSecurityOptions(app, options.security);

  auto* submit = app.add_subcommand("submit", "Submit orders from a file or the command line");
  std::string file, prefix, drop;
  std::vector<std::string> picks;
  std::string client_id;
  bool formation = false, wait = false;
  int priority = 0;
  submit->add_option("file", file, "CSV task table (seed format) or JSON orders");
  submit->add_option("--prefix", prefix, "Client id prefix for file rows (default: file stem-)");
  submit->add_option("--pick", picks, "Pick point: \"x y\" or a point name (repeat, in order)");
  submit->add_option("--drop", drop, "Drop point: \"x y\" or a point name");
  submit->add_option("--id", client_id, "Client order id (single order)");
  submit->add_option("--priority", priority, "Priority (single order)");
  submit->add_flag("--formation", formation, "Needs a 3-robot formation (single order)");
  submit->add_flag("--wait", wait, "Wait until every submitted order finishes; print a table");

  std::string id, reason;
  auto* get = app.add_subcommand("get", "Show one order");
  get->add_option("id", id, "Order id")->required();
  auto* cancel = app.add_subcommand("cancel", "Cancel an order");
  cancel->add_option("id", id, "Order id")->required();
  cancel->add_option("--reason", reason, "Kept in the order's journal");
  auto* explain = app.add_subcommand("explain", "Why the order went to its robot(s)");
  explain->add_option("id", id, "Order id")->required();
  auto* list = app.add_subcommand("list", "List orders");
  std::vector<std::string> states;
  list->add_option("--state", states, "accepted, assigned, in_progress, completed, cancelled, failed");
  auto* watch = app.add_subcommand("watch", "Print order events as they happen");
  std::vector<std::string> watch_ids;
  std::uint64_t after = 0;
  bool until_done = false;
  watch->add_option("--order", watch_ids, "Only these orders (repeat)");
  watch->add_option("--after", after, "Replay journal events after this id first");
  bool from_start = false;
  watch->add_flag("--from-start", from_start, "Replay the whole journal first");
  watch->add_flag("--until-done", until_done, "Exit when every --order is finished");
  CLI11_PARSE(app, argc, argv);
  if (std::string error; !Resolve(options.security, error)) {
    std::fprintf(stderr, "wmsctl: %s\n", error.c_str());
    return 2;
  }

  Client client(options);
  if (submit->parsed()) {
    std::vector<v1::SubmitOrderRequest> requests;
    if (!file.empty()) {
      if (!picks.empty() || !drop.empty()) {
        std::fprintf(stderr, "wmsctl: give a FILE or --pick/--drop, not both\n");
        return 1;
      }
      auto loaded = LoadOrderFile(file, prefix);
      if (!loaded.ok()) {
        std::fprintf(stderr, "wmsctl: %s\n", loaded.error.c_str());
        return 1;
      }
      requests = std::move(loaded.orders);
    } else {
      if (picks.empty() || drop.empty()) {
        std::fprintf(stderr, "wmsctl: submit needs a FILE, or --pick (at least one) and --drop\n");
        return 1;
      }
      v1::SubmitOrderRequest r;
      r.set_client_order_id(!client_id.empty() ? client_id : NewClientId());
      r.set_priority(priority);
      r.set_formation(formation);
      for (const auto& p : picks) *r.add_picks() = ParseStopArgument(p);
      *r.mutable_drop() = ParseStopArgument(drop);
      requests.push_back(std::move(r));
    }
    return Submit(client, std::move(requests), wait);
  }
  if (get->parsed() || cancel->parsed() || explain->parsed()) {
    auto ctx = client.Context();
    if (explain->parsed()) {
      v1::ExplainAllocationRequest req;
      req.set_order_id(id);
      v1::AllocationExplanation ex;
      const grpc::Status s = client.stub().ExplainAllocation(ctx.get(), req, &ex);
      if (!s.ok()) return Report("explain " + id, s);
      std::printf("%s", DescribeExplanation(ex).c_str());
      return 0;
    }
    v1::Order o;
    grpc::Status s;
    if (get->parsed()) {
      v1::GetOrderRequest req;
      req.set_order_id(id);
      s = client.stub().GetOrder(ctx.get(), req, &o);
    } else {
      v1::CancelOrderRequest req;
      req.set_order_id(id);
      req.set_reason(reason);
      s = client.stub().CancelOrder(ctx.get(), req, &o);
    }
    if (!s.ok()) return Report((get->parsed() ? "get " : "cancel ") + id, s);
    std::printf("%s", DescribeOrder(o).c_str());
    return 0;
  }
  if (list->parsed()) {
    v1::ListOrdersRequest req;
    for (const auto& name : states) {
      auto state = ParseStateName(name);
      if (!state) {
        std::fprintf(stderr, "wmsctl: unknown state '%s'\n", name.c_str());
        return 1;
      }
      req.add_states(*state);
    }
    std::printf("%s\n", OrderTableHeader().c_str());
    for (;;) {
      v1::ListOrdersResponse page;
      auto ctx = client.Context();
      const grpc::Status s = client.stub().ListOrders(ctx.get(), req, &page);
      if (!s.ok()) return Report("list", s);
      for (const auto& o : page.orders()) std::printf("%s\n", OrderTableRow(o).c_str());
      if (page.next_page_token().empty()) return 0;
      req.set_page_token(page.next_page_token());
    }
  }
  // watch
  if (until_done) {
    if (watch_ids.empty()) {
      std::fprintf(stderr, "wmsctl: --until-done needs --order\n");
      return 1;
    }
    std::map<std::string, v1::Order> done;
    if (!WaitTerminal(client, {watch_ids.begin(), watch_ids.end()}, true, &done)) return 1;
    return 0;
  }
  grpc::ClientContext ctx;
  Authorize(ctx, client.token());
  v1::WatchOrdersRequest req;
  for (const auto& w : watch_ids) req.add_order_ids(w);
  req.set_after_event_id(after);
  req.set_from_start(from_start);
  auto reader = client.stub().WatchOrders(&ctx, req);
  v1::OrderEvent e;
  while (reader->Read(&e)) {
    std::printf("%s\n", DescribeEvent(e).c_str());
    std::fflush(stdout);
  }
  const grpc::Status s = reader->Finish();
  return s.ok() ? 0 : Report("watch", s);
}

}  // namespace
}  // namespace dispatch::clients

int main(int argc, char** argv) { return dispatch::clients::Main(argc, argv); }

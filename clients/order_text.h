// Human-readable text for wmsctl: order states, events, orders, results tables, allocation
// explanations. Pure functions of proto messages; thread-safe.
#pragma once

#include <optional>
#include <string>

#include <grpcpp/support/status_code_enum.h>

#include "warehouse/dispatch/v1/orders.pb.h"

namespace dispatch::clients {

namespace v1 = ::warehouse::dispatch::v1;

// "accepted", "assigned", "in_progress", "completed", "cancelled", "failed", "unspecified".
const char* StateName(v1::OrderState state);
std::optional<v1::OrderState> ParseStateName(const std::string& name);
bool IsTerminal(v1::OrderState state);
// "INVALID_ARGUMENT", ...
const char* StatusCodeName(grpc::StatusCode code);

// "#12 t=31.40 T3 assigned -> in_progress [R5 R6 R9] R5 picked at ..."
std::string DescribeEvent(const v1::OrderEvent& event);
// Multi-line description of one order.
std::string DescribeOrder(const v1::Order& order);
// One row per order: id, client id, state, robots, created, finished, duration.
std::string OrderTableHeader();
std::string OrderTableRow(const v1::Order& order);
// Every bid with its terms (Chu2024 eqs. 1-8), winners and the reason.
std::string DescribeExplanation(const v1::AllocationExplanation& ex);

// A fresh client order id for a one-off order ("wmsctl-<unix ms>-<random>").
std::string NewClientId();

}  // namespace dispatch::clients

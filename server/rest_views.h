// The REST API's bodies (issue 15 §2: one schema for REST and gRPC): the snapshot's views as
// the messages of operator.proto and orders.proto, and the proto3 JSON mapping they travel in
// (proto field names, every field printed, enums by name). Pure functions; thread-safe.
#pragma once

#include <string>

#include <google/protobuf/message.h>

#include "engine/common/result.h"
#include "engine/map/warehouse_map.h"
#include "server/dispatcher.h"
#include "server/snapshot.h"
#include "warehouse/dispatch/v1/operator.pb.h"

namespace dispatch::server {

namespace pb = ::warehouse::dispatch::v1;

// The message as JSON text. Strings that are not UTF-8 (none should be: ids are checked on
// the way in) become U+FFFD rather than failing the answer.
std::string ToJson(const google::protobuf::Message& message);
// Parses `body` into `out`: kInvalidArgument naming what is wrong (not JSON, an unknown
// field, a value of the wrong type) so that a misspelt field is never dropped silently.
engine::Status FromJson(const std::string& body, google::protobuf::Message* out);
// An ErrorReply with `message`.
std::string ErrorJson(const std::string& message);
// `text` with every byte sequence that is not UTF-8 replaced by U+FFFD (client input echoed
// or stored: proto strings must be UTF-8).
std::string ValidUtf8(const std::string& text);

void RobotToProto(const RobotView& robot, const engine::WarehouseMap& map, pb::RobotInfo* out);
void StatusToProto(const Snapshot& snap, pb::ServiceState* out);
void RoutesToProto(const OrderRoutes& routes, pb::OrderDetail* out);
void ZonesToProto(const Snapshot& snap, const engine::WarehouseMap& map, pb::ZoneList* out);
// only_active: the intersections with a grant holder or a robot waiting.
void IntersectionsToProto(const Snapshot& snap, const engine::WarehouseMap& map, bool only_active,
                          pb::IntersectionList* out);

}  // namespace dispatch::server

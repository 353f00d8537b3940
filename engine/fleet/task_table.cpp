#include "engine/fleet/task_table.h"

#include <Eigen/Core>

#include "formats/task_table_text.h"

namespace dispatch::engine {

Result<std::vector<OrderRequest>> ParseTaskTable(std::string_view text) {
  formats::TaskTableText table = formats::ParseTaskTableText(text);
  if (!table.ok()) return InvalidArgument(table.error);
  std::vector<OrderRequest> orders;
  orders.reserve(table.rows.size());
  for (formats::TaskRow& row : table.rows) {
    OrderRequest order;
    order.id = std::move(row.task);
    order.formation = row.formation;
    for (const formats::Xy& p : row.picks) order.picks.emplace_back(Eigen::Vector2d(p[0], p[1]));
    order.drop = Eigen::Vector2d(row.drop[0], row.drop[1]);
    order.release_time = row.release;
    orders.push_back(std::move(order));
  }
  return orders;
}

}  // namespace dispatch::engine

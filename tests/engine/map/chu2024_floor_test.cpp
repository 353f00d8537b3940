#include "engine/map/chu2024_floor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace dispatch::engine {
namespace {

struct TableTask {
  std::vector<Eigen::Vector2d> picks;
  Eigen::Vector2d drop;
};

// Reads a seed task table (task,formation,picks,drop; '#' comments).
std::vector<TableTask> ReadTable(const std::string& file) {
  std::ifstream in(std::string(DISPATCH_SHARED_DIR) + "/scenarios/" + file);
  EXPECT_TRUE(in.good()) << file;
  std::vector<TableTask> tasks;
  std::string line;
  auto xy = [](const std::string& s) {
    std::istringstream in(s);
    double x = 0, y = 0;
    in >> x >> y;
    return Eigen::Vector2d(x, y);
  };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("task", 0) == 0) continue;
    std::vector<std::string> cols;
    std::istringstream row(line);
    for (std::string col; std::getline(row, col, ',');) cols.push_back(col);
    EXPECT_EQ(cols.size(), 4u) << line;
    TableTask task;
    std::istringstream picks(cols[2]);
    for (std::string p; std::getline(picks, p, ';');) task.picks.push_back(xy(p));
    task.drop = xy(cols[3]);
    tasks.push_back(task);
  }
  return tasks;
}

class Chu2024FloorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto built = BuildChu2024Floor();
    ASSERT_TRUE(built.ok()) << built.error().message;
    map_ = new WarehouseMap(std::move(built).value());
  }
  static void TearDownTestSuite() { delete map_; }
  static int CountKind(PointKind kind) {
    int n = 0;
    for (const Point& p : map_->points()) n += p.kind == kind;
    return n;
  }
  static WarehouseMap* map_;
};
WarehouseMap* Chu2024FloorTest::map_ = nullptr;

TEST_F(Chu2024FloorTest, HasTheSeedsInventory) {
  EXPECT_EQ(map_->shelves().size(), 30u);  // 5 rows x 6 columns
  EXPECT_EQ(map_->zones().size(), 6u);
  ASSERT_EQ(map_->stations().size(), 18u);
  for (const auto& s : map_->stations()) {
    EXPECT_EQ(s.capacity, 6);
    EXPECT_EQ(map_->point(s.point).kind, PointKind::kPark);
  }
  EXPECT_EQ(CountKind(PointKind::kPark), 18);
  EXPECT_GE(CountKind(PointKind::kDrop), 10);
  EXPECT_EQ(map_->intersections().size(), 42u);
  double zone_area = 0;
  for (const Zone& z : map_->zones()) zone_area += z.area;
  const Eigen::Vector2d floor = map_->floor_max() - map_->floor_min();
  EXPECT_NEAR(zone_area, floor.x() * floor.y(), 1e-9);
}

TEST_F(Chu2024FloorTest, EveryShelfHasThreeSlotsServedFromAnAisle) {
  for (const Shelf& shelf : map_->shelves()) {
    int slots_with_pick = 0;
    for (double dx : {0.25, 1.0, 1.75}) {
      const double x = shelf.min.x() + dx;
      bool served = false;
      for (const Point& p : map_->points()) {
        served |= p.kind == PointKind::kPick && std::abs(p.position.x() - x) < 1e-9 &&
                  (std::abs(p.position.y() - (shelf.max.y() + 0.75)) < 1e-9 ||
                   std::abs(p.position.y() - (shelf.min.y() - 0.75)) < 1e-9);
      }
      slots_with_pick += served;
    }
    EXPECT_EQ(slots_with_pick, 3) << shelf.name;
  }
}

TEST_F(Chu2024FloorTest, EverySeedTableCoordinateIsANodeOfTheRightKind) {
  for (const char* file : {"chu2024-table1.csv", "chu2024-table2.csv"}) {
    const auto tasks = ReadTable(file);
    EXPECT_GE(tasks.size(), 6u);
    for (const TableTask& t : tasks) {
      for (const auto& pick : t.picks) {
        double d = 1;
        map_->NearestPoint(pick, PointKind::kPick, &d);
        EXPECT_LT(d, 1e-9) << file << " pick (" << pick.transpose() << ")";
      }
      double d = 1;
      map_->NearestPoint(t.drop, PointKind::kDrop, &d);
      EXPECT_LT(d, 1e-9) << file << " drop (" << t.drop.transpose() << ")";
    }
  }
}

TEST_F(Chu2024FloorTest, OneWayLanesKeepRightOfTheirOppositeLane) {
  // Right-hand traffic: for every one-way arc the opposite lane of its aisle lies on its left,
  // never on its right.
  int checked = 0;
  for (const Arc& a : map_->arcs()) {
    if (a.single_lane()) continue;
    const Eigen::Vector2d p0 = map_->point(a.from).position, p1 = map_->point(a.to).position;
    const Eigen::Vector2d d = (p1 - p0).normalized(), mid = (p0 + p1) / 2;
    bool left = false, right = false;
    for (const Arc& b : map_->arcs()) {
      if (b.single_lane()) continue;
      const Eigen::Vector2d q0 = map_->point(b.from).position, q1 = map_->point(b.to).position;
      const Eigen::Vector2d e = (q1 - q0).normalized();
      if (e.dot(d) > -0.999) continue;  // not opposite
      const Eigen::Vector2d rel = (q0 + q1) / 2 - mid;
      const double lateral = d.x() * rel.y() - d.y() * rel.x();
      const double along = std::abs(rel.dot(d));
      if (along > (p1 - p0).norm() / 2 + (q1 - q0).norm() / 2 || std::abs(lateral) > 1.6) continue;
      (lateral > 0 ? left : right) = true;
    }
    EXPECT_TRUE(left) << map_->point(a.from).name << " -> " << map_->point(a.to).name;
    EXPECT_FALSE(right) << map_->point(a.from).name << " -> " << map_->point(a.to).name;
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

TEST_F(Chu2024FloorTest, IntersectionsHaveFourCrossingsAndApproachesOutsideThem) {
  for (const Intersection& in : map_->intersections()) {
    EXPECT_EQ(in.inner.size(), 4u) << in.name;
    EXPECT_GE(in.approach.size(), 2u) << in.name;
    for (PointId o : in.approach) {
      EXPECT_EQ(map_->IntersectionOf(o), -1);
      // The approach point leads into the region in one arc.
      bool leads_in = false;
      for (ArcId a : map_->out_arcs(o)) {
        const PointId to = map_->arc(a).to;
        leads_in |= map_->IntersectionOf(to) >= 0 &&
                    map_->intersections()[static_cast<std::size_t>(map_->IntersectionOf(to))].name == in.name;
        EXPECT_NEAR(map_->arc(a).length, 0.6, 1e-9);
      }
      EXPECT_TRUE(leads_in) << in.name << " approach " << map_->point(o).name;
    }
  }
}

TEST_F(Chu2024FloorTest, StationsHaveSingleEntryExitLanes) {
  for (const auto& s : map_->stations()) {
    ASSERT_EQ(map_->out_arcs(s.point).size(), 1u);
    ASSERT_EQ(map_->in_arcs(s.point).size(), 1u);
    EXPECT_TRUE(map_->arc(map_->out_arcs(s.point)[0]).single_lane());
  }
  const auto names = Chu2024StationNames();
  ASSERT_EQ(names.size(), 18u);
  EXPECT_EQ(names.front(), "P1");
  EXPECT_EQ(map_->stations()[17].name, names.back());
}

TEST(Chu2024FloorOptionsTest, RejectsADockFarFromEveryLane) {
  Chu2024FloorOptions options;
  options.extra_pick_docks = {{100.0, 100.0}};
  auto bad = BuildChu2024Floor(options);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("no lane point within 2 m"), std::string::npos);
}

}  // namespace
}  // namespace dispatch::engine

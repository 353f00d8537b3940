// Small LoRR problems written to a temporary folder, for the lifelong tests.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "engine/lifelong/lorr_problem.h"

namespace dispatch::engine::testing_lorr {

inline void WriteFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Writes name.json, name.map, name.agents and name.tasks into the test's temporary folder and
// returns the JSON's path. `rows` are the map's rows; agents and tasks are the files' bodies
// after their count line.
inline std::string WriteProblem(const std::string& name, const std::vector<std::string>& rows,
                                const std::vector<std::string>& agents, const std::vector<std::string>& tasks,
                                int team_size, double reveal = 1.5) {
  const std::string dir = ::testing::TempDir();
  std::string map = "type octile\nheight " + std::to_string(rows.size()) + "\nwidth " +
                    std::to_string(rows.empty() ? 0 : rows[0].size()) + "\nmap\n";
  for (const auto& row : rows) map += row + "\n";
  WriteFile(dir + "/" + name + ".map", map);
  std::string a = "# version for LoRR 2024\n" + std::to_string(agents.size()) + "\n";
  for (const auto& line : agents) a += line + "\n";
  WriteFile(dir + "/" + name + ".agents", a);
  std::string t = "# version for LoRR 2024\n" + std::to_string(tasks.size()) + "\n";
  for (const auto& line : tasks) t += line + "\n";
  WriteFile(dir + "/" + name + ".tasks", t);
  const std::string json = dir + "/" + name + ".json";
  WriteFile(json, "{\"mapFile\": \"" + name + ".map\", \"agentFile\": \"" + name + ".agents\", \"teamSize\": " +
                      std::to_string(team_size) + ", \"taskFile\": \"" + name + ".tasks\", \"numTasksReveal\": " +
                      std::to_string(reveal) + "}");
  return json;
}

inline std::string LorrExample(const std::string& relative) {
  return std::string(DISPATCH_SHARED_DIR) + "/benchmarks/lorr2024/example_problems/" + relative;
}

}  // namespace dispatch::engine::testing_lorr

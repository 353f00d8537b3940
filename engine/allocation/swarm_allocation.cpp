#include "engine/allocation/swarm_allocation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <utility>

#include "engine/common/numbers.h"

namespace dispatch::engine {
namespace {

// Heading change between two headings, in [0, pi].
double Turn(double a, double b) {
  double d = std::fmod(std::abs(a - b), 2.0 * std::numbers::pi);
  return d > std::numbers::pi ? 2.0 * std::numbers::pi - d : d;
}

// min(a, b) / max(a, b) of two fitness values (1 when both are 0 or equal): the ratios of
// Zhang et al.'s evolution speed and aggregation degree.
double Ratio(double a, double b) {
  const double hi = std::max(a, b), lo = std::min(a, b);
  if (!(hi > 0.0) || !std::isfinite(hi)) return 1.0;
  return lo / hi;
}

struct Particle {
  std::vector<std::size_t> pos;
  std::vector<double> v;
  double fit = kInf;
  std::vector<std::size_t> best;
  double best_fit = kInf;
  double previous_best_fit = kInf;  // pbest's fitness before this iteration (evolution speed)
};

class SwarmSearch {
 public:
  SwarmSearch(const SwarmProblem& p, const SwarmOptions& o, std::vector<double> dist)
      : p_(p), o_(o), dist_(std::move(dist)), m_(SwarmBlocks(p.tasks.size(), p.robots.size()).back()), rng_(o.seed) {}

  SwarmPlan Run();

 private:
  double Evaluate(const std::vector<std::size_t>& pos) {
    ++evaluations_;
    return SwarmFitness(p_, dist_, pos);
  }
  double Uniform() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng_); }
  std::size_t Below(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  void Repair(std::vector<std::size_t>& pos);
  void Update(Particle& x, const std::vector<std::size_t>& gbest, double w, double c1, double c2);
  std::vector<std::size_t> Child(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b);
  void Offer(const std::vector<std::size_t>& pos, double fit) {
    if (gbest_.empty() || fit < gbest_fit_) {  // the first, even at +infinity: gbest is a plan
      gbest_fit_ = fit;
      gbest_ = pos;
    }
  }
  // Steps 4-5: n/2 children, then the best n of the swarm and them.
  void Breed(std::vector<Particle>& swarm);
  bool Stop() const {
    if (o_.deadline && std::chrono::steady_clock::now() >= *o_.deadline) return true;
    return o_.cancelled && o_.cancelled();
  }

  const SwarmProblem& p_;
  const SwarmOptions& o_;
  const std::vector<double> dist_;
  const std::size_t m_;  // dimensions: the tasks and the idle slots
  std::mt19937_64 rng_;
  std::size_t evaluations_ = 0;
  std::vector<std::size_t> gbest_;
  double gbest_fit_ = kInf;
};

void SwarmSearch::Repair(std::vector<std::size_t>& pos) {
  // Each task given twice keeps one copy at random; the others take the unassigned tasks, in
  // random order (seed 003 step 3, last paragraph).
  std::vector<std::vector<std::size_t>> where(m_);
  for (std::size_t d = 0; d < m_; ++d) where[pos[d]].push_back(d);
  std::vector<std::size_t> missing, empty;
  for (std::size_t t = 0; t < m_; ++t) {
    if (where[t].empty()) {
      missing.push_back(t);
    } else if (where[t].size() > 1) {
      const std::size_t keep = Below(where[t].size());
      for (std::size_t k = 0; k < where[t].size(); ++k) {
        if (k != keep) empty.push_back(where[t][k]);
      }
    }
  }
  std::shuffle(missing.begin(), missing.end(), rng_);
  for (std::size_t k = 0; k < empty.size(); ++k) pos[empty[k]] = missing[k];
}

void SwarmSearch::Update(Particle& x, const std::vector<std::size_t>& gbest, double w, double c1, double c2) {
  // Eq. (2), the velocity clamped to a tenth of the index range (at least 1: the usual v_max
  // of PSO, here measured best of 0.05, 0.1 and 0.25 on the 5 x 30 batches), then eq. (3): up
  // with probability x - floor(x), within the task indices.
  const double vmax = std::max(1.0, 0.1 * static_cast<double>(m_));
  const double top = static_cast<double>(m_ - 1);
  for (std::size_t d = 0; d < m_; ++d) {
    const double here = static_cast<double>(x.pos[d]);
    double v = w * x.v[d] + c1 * Uniform() * (static_cast<double>(x.best[d]) - here) +
               c2 * Uniform() * (static_cast<double>(gbest[d]) - here);
    v = std::clamp(v, -vmax, vmax);
    x.v[d] = v;
    const double to = std::clamp(here + v, 0.0, top);
    const double down = std::floor(to);
    x.pos[d] = static_cast<std::size_t>(Uniform() < to - down ? std::min(down + 1.0, top) : down);
  }
  Repair(x.pos);
}

std::vector<std::size_t> SwarmSearch::Child(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) {
  // Step 4: a random segment of b in place of a's, repaired; mutated with the set probability.
  std::vector<std::size_t> child = a;
  std::size_t i = Below(m_), j = Below(m_);
  if (i > j) std::swap(i, j);
  for (std::size_t d = i; d <= j; ++d) child[d] = b[d];
  Repair(child);
  if (m_ > 1 && Uniform() < o_.mutation) {
    const std::size_t d = Below(m_);
    std::size_t t = Below(m_ - 1);
    if (t >= child[d]) ++t;  // another task than the one there
    child[d] = t;
    Repair(child);
  }
  return child;
}

void SwarmSearch::Breed(std::vector<Particle>& swarm) {
  const std::size_t n = swarm.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng_);
  std::vector<Particle> children;
  for (std::size_t k = 0; k + 1 < n; k += 2) {
    Particle c;
    c.pos = Child(swarm[order[k]].pos, swarm[order[k + 1]].pos);
    c.v.assign(m_, 0.0);
    c.fit = Evaluate(c.pos);
    c.best = c.pos;
    c.best_fit = c.previous_best_fit = c.fit;
    Offer(c.pos, c.fit);
    children.push_back(std::move(c));
  }
  // Elitism (step 5): the n best of the n + n/2; stable, so ties keep the older particle.
  for (Particle& c : children) swarm.push_back(std::move(c));
  std::stable_sort(swarm.begin(), swarm.end(), [](const Particle& a, const Particle& b) { return a.fit < b.fit; });
  swarm.resize(n);
}

SwarmPlan SwarmSearch::Run() {
  const std::size_t n = o_.particles;
  std::vector<Particle> swarm(n);
  // s51-s52: random permutations, their fitness, pbest and gbest.
  for (Particle& x : swarm) {
    x.pos.resize(m_);
    std::iota(x.pos.begin(), x.pos.end(), 0);
    std::shuffle(x.pos.begin(), x.pos.end(), rng_);
    x.v.assign(m_, 0.0);
    x.fit = Evaluate(x.pos);
    x.best = x.pos;
    x.best_fit = x.previous_best_fit = x.fit;
    Offer(x.pos, x.fit);
  }
  const std::size_t children = n / 2;
  const std::size_t per_iteration = o_.method == SwarmMethod::kPsoGa ? n + children
                                    : o_.method == SwarmMethod::kPso ? n
                                                                       : children;
  const std::size_t planned = o_.evaluations > evaluations_ ? (o_.evaluations - evaluations_) / per_iteration : 0;
  SwarmPlan out;
  for (std::size_t it = 0; it < planned; ++it) {
    if (Stop()) {
      out.stopped = true;
      break;
    }
    if (o_.method != SwarmMethod::kGa) {
      // Inertia and learning factors: constant for the plain PSO; for PSO-GA by iteration
      // (Ratnaweera et al.'s c1, c2) and by each particle's evolution speed and the swarm's
      // aggregation (Zhang et al.'s w).
      const double progress = planned > 1 ? static_cast<double>(it) / static_cast<double>(planned - 1) : 1.0;
      const double c1 = o_.method == SwarmMethod::kPso ? 1.494 : 2.5 - 2.0 * progress;
      const double c2 = o_.method == SwarmMethod::kPso ? 1.494 : 0.5 + 2.0 * progress;
      double mean = 0.0, round_best = kInf;
      for (const Particle& x : swarm) {
        mean += x.fit / static_cast<double>(n);
        round_best = std::min(round_best, x.fit);
      }
      const double aggregation = Ratio(round_best, mean);
      const std::vector<std::size_t> gbest = gbest_;
      for (Particle& x : swarm) {
        const double speed = Ratio(x.previous_best_fit, x.best_fit);
        const double w = o_.method == SwarmMethod::kPso ? 0.729 : 1.0 - 0.5 * (1.0 - speed) + 0.1 * aggregation;
        Update(x, gbest, w, c1, c2);
        x.fit = Evaluate(x.pos);
        x.previous_best_fit = x.best_fit;
        if (x.fit < x.best_fit) {
          x.best_fit = x.fit;
          x.best = x.pos;
        }
        Offer(x.pos, x.fit);
      }
    }
    if (o_.method != SwarmMethod::kPso) Breed(swarm);
    ++out.iterations;
  }
  out.evaluations = evaluations_;
  SwarmFitness(p_, dist_, gbest_, &out);
  const std::vector<std::size_t> blocks = SwarmBlocks(m_, p_.robots.size());
  out.sequences.resize(p_.robots.size());
  for (std::size_t k = 0; k < p_.robots.size(); ++k) {
    for (std::size_t d = blocks[k]; d < blocks[k + 1]; ++d) {
      if (gbest_[d] < p_.tasks.size()) out.sequences[k].push_back(gbest_[d]);
    }
  }
  return out;
}

}  // namespace

const char* SwarmMethodName(SwarmMethod method) {
  switch (method) {
    case SwarmMethod::kPsoGa: return "psoga";
    case SwarmMethod::kPso: return "pso";
    case SwarmMethod::kGa: return "ga";
  }
  return "?";
}

std::vector<std::size_t> SwarmBlocks(std::size_t tasks, std::size_t robots) {
  const std::size_t size = robots == 0 ? 0 : (tasks + robots - 1) / robots;
  std::vector<std::size_t> begin{0};
  for (std::size_t k = 0; k < robots; ++k) begin.push_back(begin.back() + size);
  return begin;
}

double SwarmFitness(const SwarmProblem& problem, const std::vector<double>& dist,
                    const std::vector<std::size_t>& position, SwarmPlan* plan) {
  const std::size_t n = problem.robots.size(), m = problem.tasks.size();
  const std::vector<std::size_t> blocks = SwarmBlocks(m, n);
  if (position.size() != blocks.back() || dist.size() != (n + m) * m) return kInf;
  double f_min = kInf, f_all = 0.0, f_switch = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t row = k;
    double heading = problem.robots[k].heading, travel = 0.0;
    for (std::size_t d = blocks[k]; d < blocks[k + 1]; ++d) {
      const std::size_t t = position[d];
      if (t >= m) continue;  // an idle slot
      travel += dist[row * m + t] + problem.tasks[t].length;
      f_switch += Turn(heading, problem.tasks[t].heading);
      row = n + t;
      heading = problem.tasks[t].heading;
    }
    f_min = std::min(f_min, travel);
    f_all += travel;
  }
  const double fitness = problem.a1 * f_min + problem.a2 * f_all + problem.a3 * f_switch;
  if (plan) {
    plan->fitness = fitness;
    plan->f_min = f_min;
    plan->f_all = f_all;
    plan->f_switch = f_switch;
  }
  return fitness;
}

Result<SwarmPlan> PlanSwarm(const SwarmProblem& problem, const SwarmOptions& options) {
  const std::size_t n = problem.robots.size(), m = problem.tasks.size();
  if (n == 0) return InvalidArgument("swarm allocation: no robots");
  if (m == 0) return InvalidArgument("swarm allocation: no tasks");
  if (!problem.distance) return InvalidArgument("swarm allocation: no distance oracle");
  if (options.particles < 2) return InvalidArgument("swarm allocation: fewer than 2 particles");
  if (!(options.mutation >= 0.0 && options.mutation <= 1.0)) {
    return InvalidArgument("swarm allocation: mutation probability outside [0, 1]");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (problem.robots[k].start == kNoPoint) return InvalidArgument("swarm allocation: robot " + std::to_string(k) + " has no start");
  }
  for (std::size_t j = 0; j < m; ++j) {
    if (problem.tasks[j].point == kNoPoint) return InvalidArgument("swarm allocation: task " + std::to_string(j) + " has no point");
    if (!(problem.tasks[j].length >= 0.0) || !std::isfinite(problem.tasks[j].length)) {
      return InvalidArgument("swarm allocation: task " + std::to_string(j) + " has a negative or non-finite length");
    }
  }
  // The (n + m) x m distances, each asked once.
  std::vector<double> dist((n + m) * m);
  for (std::size_t r = 0; r < n + m; ++r) {
    const PointId from = r < n ? problem.robots[r].start : problem.tasks[r - n].end_point();
    for (std::size_t j = 0; j < m; ++j) {
      const double d = problem.distance(from, problem.tasks[j].point);
      if (std::isnan(d) || d < 0.0) {
        return InvalidArgument("swarm allocation: distance to task " + std::to_string(j) + " is negative or NaN");
      }
      dist[r * m + j] = d;
    }
  }
  return SwarmSearch(problem, options, std::move(dist)).Run();
}

}  // namespace dispatch::engine

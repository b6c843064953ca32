// Speed and separation monitoring figures (docs/PERSON.md, docs/BENCHMARKS.md "A person in the
// cell"), in the LBR iiwa cell with the 3-finger gripper, the arm moved through its own
// operations (MoveToPose: the Arm component, its motion planner, the simulator's controller with
// the speed override):
//   build/bench/ssm_bench stop FIRST_SEED COUNT
//     the arm's stopping time T_s and distance S_s = k_s v: a fast motion across the table,
//     the monitor's stop input set at the motion's fastest instant (found in a first run of the
//     same seed), the time until the arm's fastest point is below 1 cm/s and the path that point
//     covered meanwhile; the numbers SpeedSeparationParams must cover.
//   build/bench/ssm_bench random FIRST_SEED COUNT SECONDS
//     the randomized check: the arm moves to random poses over the table while the person of
//     sim/scenes/person_random.json reaches at random (seeded by the cell's seed), for SECONDS
//     of simulated time per seed; the monitor's record (violations of the protective distance
//     while the arm moves faster than 0.25 m/s, contact with the person, stops).
// Run from the repository root.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "core/paths.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

using namespace costar;

namespace {

std::unique_ptr<workcell::Workcell> cellWith(const std::string& scene, std::uint64_t seed) {
  return workcell::makeWorkcell({.name = "iiwa-3f-sim",
                                 .scene = dataRoot() / "sim/scenes" / scene,
                                 .seed = seed,
                                 .memory_only = true,
                                 .test_oracle_perception = true});
}

component::OperationResult moveTo(workcell::Workcell& cell, const Eigen::Vector3d& at, double yaw, double speed,
                                  const std::function<void(const component::OperationResult&)>& progress = {}) {
  return workcell::runOperation(
      cell, "MoveToPose", {{"pose", world::poseFromXyzRpy(at.x(), at.y(), at.z(), M_PI, 0, yaw)}, {"speed", speed}},
      std::chrono::seconds(60), progress, std::chrono::milliseconds(2));
}

struct Stop {
  double speed = 0.0;     // the fastest point's speed when the stop input was set, m/s
  double time = 0.0;      // until below 1 cm/s, s
  double distance = 0.0;  // the fastest point's path meanwhile (speed integrated), m
};

Stop measureStop(std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> x(0.35, 0.65);
  const Eigen::Vector3d from(x(random), -0.35, 0.25);
  const Eigen::Vector3d to(x(random), 0.35, 0.12);
  // First run: when is the arm fastest?
  double fastest = 0.0;
  double fastest_at = 0.0;
  {
    const auto cell = cellWith("person_away.json", seed);
    sim::Simulation& simulation = *cell->simulation();
    moveTo(*cell, from, 0.0, 1.0);
    const double start = toSeconds(simulation.time().time_since_epoch());
    moveTo(*cell, to, 1.2, 1.0, [&](const component::OperationResult&) {
      const double speed = simulation.separation()->arm_speed;
      if (speed > fastest) {
        fastest = speed;
        fastest_at = toSeconds(simulation.time().time_since_epoch()) - start;
      }
    });
  }
  // Second run: the stop input at that instant.
  Stop stop;
  const auto cell = cellWith("person_away.json", seed);
  sim::Simulation& simulation = *cell->simulation();
  moveTo(*cell, from, 0.0, 1.0);
  const double start = toSeconds(simulation.time().time_since_epoch());
  double stopped_at = -1.0;
  double last = start;
  moveTo(*cell, to, 1.2, 1.0, [&](const component::OperationResult&) {
    const double now = toSeconds(simulation.time().time_since_epoch());
    const double speed = simulation.separation()->arm_speed;
    if (stopped_at < 0.0 && now - start >= fastest_at) {
      simulation.setStopInput(true);
      stopped_at = now;
      stop.speed = speed;
    } else if (stopped_at >= 0.0 && stop.time == 0.0) {
      stop.distance += speed * (now - last);
      if (speed < 0.01) {
        stop.time = now - stopped_at;
        simulation.setStopInput(false);
      }
    }
    last = now;
  });
  return stop;
}

struct RandomRun {
  sim::SeparationRecord record;
  int moves = 0;
  int failed = 0;
  double seconds = 0.0;
};

RandomRun randomRun(std::uint64_t seed, double seconds) {
  RandomRun run;
  const auto cell = cellWith("person_random.json", seed);
  sim::Simulation& simulation = *cell->simulation();
  std::mt19937_64 random(seed * 7919 + 1);
  std::uniform_real_distribution<double> x(0.3, 0.7);
  std::uniform_real_distribution<double> y(-0.4, 0.4);
  std::uniform_real_distribution<double> z(0.08, 0.35);
  std::uniform_real_distribution<double> yaw(-1.5, 1.5);
  std::uniform_real_distribution<double> speed(0.5, 1.0);
  while (toSeconds(simulation.time().time_since_epoch()) < seconds) {
    const component::OperationResult result =
        moveTo(*cell, Eigen::Vector3d(x(random), y(random), z(random)), yaw(random), speed(random));
    ++run.moves;
    run.failed += result.state == component::OperationState::kSuccess ? 0 : 1;
  }
  run.record = *simulation.separationRecord();
  run.seconds = toSeconds(simulation.time().time_since_epoch());
  return run;
}

int usage() {
  std::fprintf(stderr,
               "usage: ssm_bench stop FIRST_SEED COUNT\n"
               "       ssm_bench random FIRST_SEED COUNT SECONDS\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    return usage();
  }
  const std::string mode = argv[1];
  const std::uint64_t first = std::strtoull(argv[2], nullptr, 10);
  const int count = std::atoi(argv[3]);
  const sim::SpeedSeparationParams params;
  if (mode == "stop") {
    double worst_time = 0.0;
    double worst_k = 0.0;
    std::printf("seed  speed_m_s  stop_time_s  stop_distance_m  k_s_s\n");
    for (int i = 0; i < count; ++i) {
      const Stop stop = measureStop(first + static_cast<std::uint64_t>(i));
      const double k = stop.speed > 0.0 ? stop.distance / stop.speed : 0.0;
      worst_time = std::max(worst_time, stop.time);
      worst_k = std::max(worst_k, k);
      std::printf("%4llu  %9.3f  %11.3f  %15.4f  %5.3f\n", static_cast<unsigned long long>(first + i), stop.speed,
                  stop.time, stop.distance, k);
    }
    std::printf("worst: T_s %.3f s (parameter %.3f), k_s %.3f s (parameter %.3f): %s\n", worst_time,
                params.stopping_time, worst_k, params.stopping_distance_per_speed,
                worst_time <= params.stopping_time && worst_k <= params.stopping_distance_per_speed ? "covered"
                                                                                                    : "NOT COVERED");
    return 0;
  }
  if (mode == "random" && argc >= 5) {
    const double seconds = std::atof(argv[4]);
    double total = 0.0;
    double fast = 0.0;
    double stopped = 0.0;
    std::uint64_t violations = 0;
    std::uint64_t contacts = 0;
    std::uint64_t stopped_contacts = 0;
    double min_margin = 1e9;
    double min_fast = 1e9;
    int stops = 0;
    int moves = 0;
    int failed = 0;
    std::printf(
        "seed  sim_s  moves  failed  fast_s  stopped_s  stops  min_sep_fast_m  min_margin_fast_m  violation_steps  "
        "contact_steps  max_contact_N  stopped_contact_steps  max_stopped_contact_N\n");
    for (int i = 0; i < count; ++i) {
      const RandomRun run = randomRun(first + static_cast<std::uint64_t>(i), seconds);
      const sim::SeparationRecord& r = run.record;
      std::printf("%4llu  %5.0f  %5d  %6d  %6.1f  %9.1f  %5d  %14.3f  %17.3f  %15llu  %13llu  %13.1f  %21llu  %21.1f\n",
                  static_cast<unsigned long long>(first + i), r.seconds, run.moves, run.failed, r.fast_seconds,
                  r.stopped_seconds, r.stops, r.min_separation_fast, r.min_margin_fast,
                  static_cast<unsigned long long>(r.violation_steps), static_cast<unsigned long long>(r.contact_steps),
                  r.max_contact_force, static_cast<unsigned long long>(r.stopped_contact_steps),
                  r.max_stopped_contact_force);
      stopped_contacts += r.stopped_contact_steps;
      total += r.seconds;
      fast += r.fast_seconds;
      stopped += r.stopped_seconds;
      violations += r.violation_steps;
      contacts += r.contact_steps;
      min_margin = std::min(min_margin, r.min_margin_fast);
      min_fast = std::min(min_fast, r.min_separation_fast);
      stops += r.stops;
      moves += run.moves;
      failed += run.failed;
    }
    std::printf(
        "total: %.0f s simulated, %d moves (%d not finished), %.1f s faster than 0.25 m/s, %.1f s stopped, %d "
        "protective stops, min separation while fast %.3f m, min margin over S_p while fast %.3f m, %llu violation "
        "steps, %llu steps of contact with the arm moving, %llu with the arm stopped (the person ran into it)\n",
        total, moves, failed, fast, stopped, stops, min_fast, min_margin, static_cast<unsigned long long>(violations),
        static_cast<unsigned long long>(contacts), static_cast<unsigned long long>(stopped_contacts));
    return violations == 0 && contacts == 0 ? 0 : 1;
  }
  return usage();
}

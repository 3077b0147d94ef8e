// Parameters of the SLAM core, one struct per component, with the defaults the project ships.
// Names match the ROS parameters / dynamic_reconfigure fields of the same meaning.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace evidential_slam {

// Forward (plausibility) and inverse (GBT) laser models, algorithm.md §3-§4.
struct SensorModelConfig {
  double hit_sigma = 0.025;      // σ of a hit's position along the beam (m), inverse model
  double forward_sigma = 0.025;  // σ_f of the forward model (m)
  double forward_window = 3.0;   // k_f: half-width of the forward hit window in σ_f
  double free_gap = 3.0;         // k_i: Θ gap left in front of a hit, in σ
  double random_weight = 0.2;    // r: random-measurement discount / plausibility floor
  // σ_f after a long step (SlamConfig::isLongStep; 0 = forward_sigma there too).
  // applyRealRobotPreset: 0.05, so the logs whose scans are about 1 m apart (intel, aces: 97-99 %
  // of their steps long) are weighed with the wider window, and a dense log (freiburg-079: 9 %)
  // keeps the cheaper one.
  double long_step_forward_sigma = 0.0;
  // Share of a cell's ignorance m̃(Θ) that the forward model lets stop the beam, the rest letting
  // it pass as free space would. 1 is the paper's disjunctive rule: a beam ending in never-observed
  // space is fully plausible (pl ≈ 1), more than one ending on a mapped wall, which can favour a
  // particle whose scan falls off its map. With 0.5 such a beam has pl ≈ 0.89 (0.05 m cells,
  // σ_f = 2.5 cm; a certain wall at the range: 0.998). Measured at 0.5: aces-synth seeds 1 and 2
  // no longer collapse (0.31, 0.32 m against 6.3, 3.9), but aces seeds 4 and 5 do (6.4, 7.8 m
  // against 0.42, 0.28). Kept at the paper's 1.
  double forward_unknown_weight = 1.0;
  // The forward model reads a cell's conflict m(∅) = 1 - e^{-λ} as ignorance (Yager's rule)
  // instead of normalising it away (Dempster's): m(o) and m(e) scaled by e^{-λ}, the rest on Θ.
  // Space the map holds free where scans have seen something (a person, a moved door) then
  // explains a hit there; with normalised masses such a beam gets the floor r at every scan.
  // On in applyRealRobotPreset: on the real logs (seeds 1-5) it ended aces-synth's two
  // collapses and ran 30-40 % faster; off by default: on simul.rawlog it measured 0.10-0.15 m
  // against 0.06-0.09 m, and range_030_bearing_015.rawlog grew from 527 to 604 MB.
  bool forward_conflict_as_unknown = false;
  double prior_occupied = 0.4;  // p_o: simple-support occupancy prior of the inverse model
  double usable_range = 20.0;   // m; longer rays only clear space up to here
  double min_range = 0.05;      // m; shorter rays are ignored (robot body, dust)
  bool clear_no_return = true;  // no-return rays clear space up to usable_range
  int weight_beam_stride = 1;   // use every n-th beam for particle weights

  bool isValid(std::string* why) const;
  // The model for a sensor that declares `range_sigma` of range noise: the σ's are never below
  // the sensor's (σ_i ≥ σ_range, σ_f ≥ √(σ_range² + Δ²/12), algorithm.md §3), so a noisy laser
  // is not treated as a precise one.
  SensorModelConfig forSensorNoise(double range_sigma, double resolution) const;
};

// Odometry motion model (Probabilistic Robotics, sample_motion_model_odometry).
struct MotionModelConfig {
  // Defaults sized on simul.rawlog's odometry (per 0.6 m step: σ 8.5 cm along, 3 cm across,
  // 0.74°); wider rotation noise throws samples beyond what the matcher recovers.
  double alpha_rot_rot = 0.02;      // rotation noise from rotation (rad²/rad²); real preset 0.005
  double alpha_rot_trans = 0.0005;  // rotation noise from translation (rad²/m²)
  double alpha_trans_trans = 0.03;  // translation noise from translation (m²/m²)
  double alpha_trans_rot = 0.01;    // translation noise from rotation (m²/rad²)
  double min_sigma_xy = 0.005;      // m, floor so particles always spread a little
  double min_sigma_theta = 0.002;   // rad

  bool isValid(std::string* why) const;
};

// Refinement of each particle's sampled pose against its own map: ICP on nearest occupied cells
// (wide capture), then a short hill climb on a smooth endpoint score (sub-cell precision).
struct ScanMatcherConfig {
  bool enabled = true;
  double search_radius = 0.4;        // m around each endpoint searched for an occupied cell
  double occupied_threshold = 0.25;  // m̃(o) that makes a cell a match target (at most one hit's)
  // At most; applyRealRobotPreset: 30. Its steps shrink slowly (nearest-cell matches change as
  // the pose moves): on aces-synth 81 % of the calls used all of 12 and 35 % all of 60, and
  // stopping at 12 left real odometry's proposals short of their match (aces-synth seeds 1-10:
  // 4 over 0.3 m; 1 with 30; but seeds 11-30, not used to choose it: 11 with 12, 14 with 30, so
  // no gain shown on aces-synth). Simulated odometry starts ICP near its match: simul.rawlog gives
  // the same trajectory with 30, range_030_bearing_015.rawlog a worse one
  // (docs/decisions.md#icp-iterations).
  int icp_iterations = 12;
  // ICP minimises each endpoint's distance to the line through the target cells around its match
  // (their axis of least spread is the normal), by Gauss-Newton steps, so it does not slide along
  // walls; point to point where those cells do not line up (a corner, a lone cell). false: the
  // distance to the matched cell's centre everywhere (closed-form rigid alignment).
  bool point_to_line = true;
  double linear_step = 0.02;   // m, first hill-climb step, halved at every refinement
  double angular_step = 0.01;  // rad
  int refinements = 3;         // number of step halvings
  int max_iterations = 20;     // hill-climb moves per refinement level, at most
  double score_sigma = 0.05;   // m, spread of the endpoint score kernel
  // rad between matched beams (2°): a 0.5° laser is matched on every 4th usable beam, a 1° one on
  // every 2nd, so the matching costs the same per scan whatever the laser's density.
  double beam_spacing = 0.03490658503988659;
  // Particle k refines its pose on the scan's beam subset k mod stride (the stride's interleaved
  // subsets, beam_spacing apart each; endpoints()): between them the particles match every beam,
  // each at the cost of one subset, and the weights, which read every beam, choose among them.
  // false: every particle on subset 0. The wide-basin match always uses subset 0. Off, also in
  // the real preset: on aces-synth it gave 7 misses of 0.3 m in seeds 11-30 against 14, but the
  // same 7 as without it in fresh seeds 31-50 (docs/decisions.md#interleaved-beam-subsets).
  bool interleave_subsets = false;
  // Beam spacing (rad) for a long step: when the odometry moved at least long_step_distance or
  // turned at least long_step_angle since the last processed scan (isLongStep; these two also
  // define the long step of sensor.long_step_forward_sigma), the whole matching (wide-basin
  // match and refinement) uses long_step_beam_spacing instead of beam_spacing. A long step leaves
  // the prediction further from the match and the scan less overlap with the map, so the match
  // gets more endpoints where it needs them and the cheaper spacing where steps are short. 0 = off.
  // applyRealRobotPreset: 1°. Every beam matched everywhere took aces-synth (seeds 1-50) from 22
  // misses of 0.3 m to 13 but freiburg-079 below 20x real time; after long steps only, fresh
  // aces-synth seeds 61-100 missed on 15 against 19, aces (seeds 1-20) met 0.5 m on all, and
  // freiburg-079 (9 % of its steps long) kept 21.5-22.5x
  // (docs/decisions.md#long-step-beam-spacing).
  double long_step_beam_spacing = 0.0;
  double long_step_distance = 0.8;  // m
  double long_step_angle = 0.3;     // rad (17°)
  // True when an odometry step of `distance` m and `angle` rad is long.
  bool isLongStep(double distance, double angle) const {
    return distance >= long_step_distance || std::abs(angle) >= long_step_angle;
  }
  double min_match_fraction =
      0.2;  // below this fraction of endpoints matched, keep the sampled pose
  // Wide-basin match (applyRealRobotPreset): before the particles are sampled, each hypothesis
  // (map and pose) is matched once by ICP from its odometry prediction; unless that explains the
  // scan, also from the prediction turned by ±heading_step, ... ±heading_window and from no and
  // from reversed translation, the forward model choosing. The particles are then sampled around
  // the chosen pose. ICP alone recovers a few degrees and ~0.3 m; real wheel odometry is off by up
  // to 20° between processed scans (a slipping turn) and may report speed without its sign
  // (Freiburg 079's never goes backwards, the robot does 168 times). 0 disables it.
  double heading_window = 0.0;   // rad, half-width; applyRealRobotPreset: 0.35 (20°)
  double heading_step = 0.0873;  // rad (5°), spacing of the turned starts
  bool isValid(std::string* why) const;
  // Matching for a sensor with `range_sigma` of range noise: kernel and search radius widened,
  // and a cell is a match target once it holds one hit's worth of occupied mass
  // (`hit_occupied_mass`, the inverse model's m(o) at the hit) if that is below the threshold:
  // a 0.3 m-noise laser puts only 0.085 on a hit cell, so 0.25 would leave ICP without targets.
  // ICP is point to point when the noise exceeds a cell (`resolution`): a wall's evidence is then
  // a band several cells thick with its targets scattered through it, and the line through a few
  // of them is not the wall's. Its endpoints are then also matched at half the beam_spacing: each
  // places the wall so loosely that the match needs more of them (range_030_bearing_015.rawlog,
  // 0.3 m noise, seeds 1-3: 0.54 / 0.54 / 0.37 m with 2°, 0.33 / 0.57 / 0.33 m with 1°).
  ScanMatcherConfig forSensorNoise(double range_sigma, double hit_occupied_mass,
                                   double resolution) const;
};

struct SlamConfig {
  int particles = 100;               // K (paper: 100)
  double resolution = 0.05;          // m per cell
  uint64_t seed = 1;                 // RNG seed; runs are deterministic for a seed and thread count
  int threads = 0;                   // worker threads; 0 = all cores
  double update_min_distance = 0.5;  // m the robot must travel before a scan is processed
  double update_min_angle = 0.17453292519943295;  // rad (10°) it must turn, alternatively
  // The scan's log plausibility enters the weights divided by this (beams are not independent).
  // algorithm.md's 1/(γK) with γ = 3 flattens the weights as K grows; at K = 100 that left the
  // filter almost unable to select (simul.rawlog, K = 100: ATE 0.89 m; 0.25 m with T = 30, 0.16 m
  // with T = 20).
  double likelihood_temperature = 20.0;
  double resample_threshold = 0.5;  // resample when N_eff < threshold * K
  // The weights also score the distance each particle went along the odometry's direction of
  // travel (alongTrackLogPrior, floored at the 3 nats of a missed or reversed translation), which
  // a corridor leaves unconstrained. On in applyRealRobotPreset: with conflict read as ignorance
  // it took the real logs' misses (seeds 1-5) from 3 of 23 runs to 1 of 25 (aces-synth 0.44 m).
  bool along_track_prior = false;
  // Particles that share a map and whose refined poses differ by less than this are one hypothesis:
  // they take the same pose and the scan is integrated once for all of them (0 disables).
  double merge_distance = 0.005;  // m
  double merge_angle = 0.0025;    // rad
  // A hypothesis whose position the scan fixes every way (ScanMatcher::translationConstraint, the
  // smaller over the larger eigenvalue of ICP's translation information, at least
  // constrained_merge_ratio; measured at its wide-basin match when that runs, else at its first
  // particle's refined pose) merges its particles within constrained_merge_distance /
  // constrained_merge_angle instead. Along a corridor (ratio near 0) the spread is the filter's
  // only memory of the distance travelled, so it is kept there. Only for a laser matched point to
  // line (a noisy laser's banded walls read as fixed everywhere). 0 = off. simul.rawlog (seeds
  // 1-3) takes 31 % less time with it at the same accuracy, freiburg-079 23-25x real time instead
  // of 18-19x (docs/decisions.md#constrained-merge).
  double constrained_merge_ratio = 0.5;
  double constrained_merge_distance = 0.05;  // m
  double constrained_merge_angle = 0.02;     // rad
  SensorModelConfig sensor;
  MotionModelConfig motion;
  ScanMatcherConfig matcher;

  bool isValid(std::string* why) const;
  // True when an odometry step is long (ScanMatcherConfig::isLongStep) and a long-step setting is
  // on (matcher.long_step_beam_spacing or sensor.long_step_forward_sigma).
  bool isLongStep(double distance, double angle) const {
    return (matcher.long_step_beam_spacing > 0.0 || sensor.long_step_forward_sigma > 0.0) &&
           matcher.isLongStep(distance, angle);
  }
};

// The preset for real robots' logs (offline runner --preset real, config/real.yaml for the node):
// sets only what differs from the defaults, which were sized on GridmapNavSimul's simulated
// odometry (within 3° and 10 % per step): the wide-basin match of each hypothesis
// (matcher.heading_window = 0.35 rad), which real wheel odometry needs (heading errors up to 20°
// between processed scans, translation reported without its sign) and which costs time on logs
// that do not; the forward model reading conflict as ignorance
// (sensor.forward_conflict_as_unknown), for the people and moved doors real logs hold; the
// weights' along-track prior (along_track_prior), for the corridors where a scan does not fix the
// distance travelled; ICP to 30 iterations (matcher.icp_iterations); every beam of a 1° laser
// matched after a long step (matcher.long_step_beam_spacing = 1°), where
// the logs whose scans are about 1 m apart (intel, aces) are less accurate at the 2° that keeps a
// dense log (freiburg-079) above 20x real time; less rotation noise from rotation
// (motion.alpha_rot_rot = 0.005): the particles are sampled around the wide-basin match, which
// has already taken out the odometry's heading error, and the default's spread (±8° at 1σ for a
// 57° turn) throws them beyond what their refinement recovers; and a wider forward model
// after a long step (sensor.long_step_forward_sigma = 0.05 m): on fresh aces-synth seeds 197-226
// the wider model everywhere missed 0.3 m on 1 of 30 against 3 (0 against 3 on 197-216, where it
// was chosen; 1 against 0 on 217-226), at 10 % less CPU and 25 % more memory there, but 14 % more
// CPU on freiburg-079's 0.5° scans, which long steps only spares.
void applyRealRobotPreset(SlamConfig* config);

// The run-time SLAM parameters by their ROS names (cfg/EvidentialSlam.cfg), for front ends
// without a parameter server: the offline runner's --param NAME=VALUE sets what the node's
// rosparam / dynamic_reconfigure field of the same name sets.
std::vector<std::string> slamParameterNames();
// Sets one of them from its text (a number; true/false or 1/0 for a switch). False, with a
// one-line reason, for an unknown name or a value that does not parse or is out of range for its
// type; the ranges between parameters are SlamConfig::isValid's to check.
bool setSlamParameter(const std::string& name, const std::string& value, SlamConfig* config,
                      std::string* why);

}  // namespace evidential_slam

// `lvox render SCENE.json -o OUT.exr [...]`: flags override the scene file.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "src/app/commands.h"
#include "src/app/rank_times.h"
#include "src/app/render_output.h"
#include "src/app/version_info.h"
#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/file_hash.h"
#include "src/core/image_io.h"
#include "src/core/progress.h"
#include "src/render/cloud_export.h"
#include "src/render/layers.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"
#include "volume/rte/method.h"
#include "volume/volume_settings.h"

namespace lvox {
namespace {

struct RenderFlags {
  std::string scene;
  std::string output;
  std::string report;
  std::optional<std::string> mode;
  std::optional<int> spp;
  std::optional<int> adaptiveSpp;
  std::optional<int> maxBounces;
  std::optional<int64_t> seed;
  std::optional<int> threads;
  std::optional<std::string> maxMemory;
  std::optional<std::string> maxEvaluations;
  std::optional<int> width, height;
  std::optional<std::string> solver;
  std::optional<float> step;
  std::optional<float> tolerance;
  uint64_t firstSample = 0;
  double timeLimit = 0.0;
  std::string convergenceReference;
  std::string convergenceCsv;
  std::string layers;
  std::string exportCloud;
  double exposure = 0.0;
  bool half = false;
  bool quiet = false;
};

void stageConvergenceCsv(OutputSet& set, const std::string& path,
                         const std::vector<ConvergencePoint>& points) {
  std::ostringstream csv;
  csv << "spp,seconds,delta_percent,relmse,rmse,psnr_db,max_abs\n";
  for (const ConvergencePoint& p : points)
    csv << p.spp << ',' << p.seconds << ',' << p.error.deltaPercent << ',' << p.error.relMse << ','
        << p.error.rmse << ',' << p.error.psnrDb << ',' << p.error.maxAbs << '\n';
  const std::string text = csv.str();
  set.stage(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw std::runtime_error("cannot write the CSV");
  });
}

// Ctrl-C during a Monte Carlo render: the first stops it after the pass under way (its
// finished samples are written as a valid, mergeable image); a second quits at once,
// removing any output being staged.
std::atomic<bool> g_stopRequested{false};

extern "C" void onInterrupt(int sig) {
  if (!g_stopRequested.exchange(true)) return;
  removeStagedTemporaries();
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// Installs onInterrupt for SIGINT while alive (when enabled), restoring the previous action.
class InterruptGuard {
 public:
  explicit InterruptGuard(bool enabled) : enabled_(enabled) {
    if (!enabled_) return;
    g_stopRequested = false;
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &previous_);
  }
  ~InterruptGuard() {
    if (enabled_) ::sigaction(SIGINT, &previous_, nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  bool enabled_;
  struct sigaction previous_ {};
};

// The flags that set a scene field, as overrides the scene loader checks like the field.
std::vector<SettingOverride> overrides(const RenderFlags& f) {
  std::vector<SettingOverride> out;
  addOverride(out, flags::kMode, f.mode);
  addOverride(out, flags::kSpp, f.spp);
  addOverride(out, flags::kAdaptiveSpp, f.adaptiveSpp);
  addOverride(out, flags::kMaxBounces, f.maxBounces);
  addOverride(out, flags::kSeed, f.seed);
  addOverride(out, flags::kThreads, f.threads);
  addOverride(out, flags::kMaxMemory, f.maxMemory);
  addOverride(out, flags::kMaxEvaluations, f.maxEvaluations);
  addOverride(out, flags::kWidth, f.width);
  addOverride(out, flags::kHeight, f.height);
  addOverride(out, flags::kSolver, f.solver);
  addOverride(out, flags::kStep, f.step);
  addOverride(out, flags::kTolerance, f.tolerance);
  return out;
}

// A setting's default as --help shows it: "0.1", "0.001".
std::string shortNumber(float value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

// --layers: "all" is every layer the mode has; the variance is Monte Carlo's only (pcb's
// error is mostly bias, which a sample variance does not show).
LayerSet parseLayers(const std::string& list, Mode mode) {
  if (list.empty()) return {};
  const LayerSet layers = LayerSet::parse(list, mode == Mode::kMc, "--layers");
  if (layers.has(Layer::kVariance) && mode != Mode::kMc)
    throw InputError("--layers", "variance",
                     "is a layer of mode mc only (a pcb image's error is mostly bias, which a "
                     "sample variance does not measure)");
  return layers;
}

// --export-cloud: a .ply or .vdb path that is no input and no other output, in a mode that
// builds a point cloud.
void checkExportCloud(const std::string& path, Mode mode, const RenderOutputs& outputs,
                      const std::string& reportPath, const std::vector<std::string>& inputs) {
  checkCloudPath(path, "--export-cloud");
  if (!isPointBased(mode))
    throw InputError(path, "--export-cloud",
                     "needs mode pcb or pcb-surfels (mode " + std::string(modeName(mode)) +
                         " builds no point cloud)");
  checkOutputPath(path, "--export-cloud", inputs);
  for (const std::string& other : {outputs.exrPath(), outputs.pngPath(), reportPath})
    if (!other.empty() &&
        std::filesystem::weakly_canonical(other) == std::filesystem::weakly_canonical(path))
      throw InputError(path, "--export-cloud", "is the same file as another output");
}

// The profiling lines of the point-based modes: phase times, element counts, memory.
void printPointCloudSummary(const Report& report) {
  auto count = [&](const char* key) { return report.count(key); };
  auto megabytes = [&](const char* key) {
    auto it = report.memory.find(key);
    return it == report.memory.end() ? 0.0 : static_cast<double>(it->second) * 1e-6;
  };
  std::string phases;
  for (const char* phase : {"surfel_sampling", "lvoxel_sampling", "octree_build", "direct_cache",
                            "interreflection", "gather_grid", "render"}) {
    auto it = report.times.find(phase);
    if (it == report.times.end()) continue;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s %.2f s", phases.empty() ? "" : ", ", phase, it->second);
    phases += buf;
  }
  std::fprintf(stderr, "lvox: phases: %s\n", phases.c_str());
  std::fprintf(stderr,
               "lvox: cloud: %llu surfels, %llu lvoxels, %llu nodes; %.1f MB elements, %.1f MB "
               "octree, %.1f MB interreflection weights, %.1f MB lvoxel light (%.0f B per "
               "element); peak RSS %.0f MB\n",
               static_cast<unsigned long long>(count("surfels")),
               static_cast<unsigned long long>(count("lvoxels")),
               static_cast<unsigned long long>(count("octree_nodes")), megabytes("point_cloud"),
               megabytes("octree"), megabytes("interreflection_operator"),
               megabytes("lvoxel_light"), megabytes("bytes_per_element") * 1e6,
               megabytes("peak_rss"));
}

void printSummary(const Scene& scene, const Report& report, const std::string& output) {
  const std::string mode(modeName(scene.render.mode));
  const double seconds = report.times.at("total");
  uint64_t rays = 0;
  for (const char* key : {"camera_rays", "shadow_rays", "gather_rays", "path_rays"})
    rays += report.count(key);
  std::fprintf(stderr, "lvox: %s %dx%d %s spp, %s mode: %.2f s, %.2f Mrays/s -> %s\n",
               std::filesystem::path(scene.path).filename().c_str(), scene.world.camera.width,
               scene.world.camera.height, report.settings.at("spp").c_str(), mode.c_str(), seconds,
               seconds > 0 ? static_cast<double>(rays) / seconds * 1e-6 : 0.0, output.c_str());
  if (isPointBased(scene.render.mode)) printPointCloudSummary(report);
  if (const uint64_t invalid = report.count("invalid_samples"); invalid > 0)
    std::fprintf(stderr, "lvox: warning: %llu invalid (NaN/Inf/negative) samples were zeroed\n",
                 static_cast<unsigned long long>(invalid));
  for (const std::string& w : report.warnings)
    std::fprintf(stderr, "lvox: warning: %s\n", w.c_str());
}

// Split over ranks, every rank renders its share of every pass: a time budget or a
// convergence record would need the ranks to agree on each pass.
void checkDistributable(const RenderFlags& flags, const Collective& team) {
  if (!team.distributed()) return;
  const char* why = "is not available in a render split over MPI ranks (docs/cluster.md)";
  if (flags.timeLimit != 0.0) throw InputError("--time-limit", "", why);
  if (!flags.convergenceReference.empty()) throw InputError("--convergence", "", why);
}

int runRender(const RenderFlags& flags, Collective& team) {
  const auto start = std::chrono::steady_clock::now();
  // The progress line: on a terminal only, from the rank that prints the summary.
  Progress::global().enable(!flags.quiet && team.isRoot() && isatty(STDERR_FILENO) != 0);
  if (flags.timeLimit != 0.0 && !(std::isfinite(flags.timeLimit) && flags.timeLimit > 0.0))
    throw InputError("--time-limit", "", "must be a finite number of seconds > 0");
  checkDistributable(flags, team);
  Report report;
  Scene scene;
  {
    PhaseTimer timer(report, "scene_load");
    scene = loadScene(flags.scene, overrides(flags));
  }
  report.settings["scene"] = scene.path;
  report.settings["scene_hash"] = hashFiles(scene.inputFiles);
  report.settings["version"] = versionString();
  report.settings["revision"] = gitRevision();
  // Every file the command reads: no output may replace one.
  std::vector<std::string> inputs = scene.inputFiles;
  if (!flags.convergenceReference.empty()) inputs.push_back(flags.convergenceReference);
  RenderOutputs outputs(flags.output, flags.report, inputs);
  outputs.setPreviewExposure(flags.exposure);
  RenderPlan plan;
  plan.spp = scene.render.spp;
  plan.firstSample = flags.firstSample;
  plan.timeLimitSeconds = flags.timeLimit;
  plan.team = &team;
  plan.layers = parseLayers(flags.layers, scene.render.mode);
  ExportedCloud cloud;
  if (!flags.exportCloud.empty()) {
    checkExportCloud(flags.exportCloud, scene.render.mode, outputs, flags.report, inputs);
    plan.cloudOut = &cloud;
  }
  Image reference;
  if (!flags.convergenceReference.empty()) {
    if (flags.convergenceCsv.empty())
      throw InputError(flags.convergenceReference, "--convergence", "needs --convergence-csv");
    checkOutputPath(flags.convergenceCsv, "--convergence-csv", inputs);
    for (const std::string& other : {outputs.exrPath(), outputs.pngPath(), flags.report})
      if (!other.empty() && std::filesystem::weakly_canonical(other) ==
                                std::filesystem::weakly_canonical(flags.convergenceCsv))
        throw InputError(flags.convergenceCsv, "--convergence-csv",
                         "is the same file as another output");
    reference = readExr(flags.convergenceReference);
    if (reference.width != scene.world.camera.width ||
        reference.height != scene.world.camera.height)
      throw InputError(flags.convergenceReference, "--convergence",
                       "has a different size than the scene's camera");
    plan.reference = &reference;
  }
  // Monte Carlo renders are long: the first Ctrl-C keeps the finished samples (in one
  // process; a split render stops as a whole, by its launcher).
  // Not with adaptive samples: their extra samples need every first one.
  const bool stoppable = scene.render.mode == Mode::kMc && !team.distributed() &&
                         adaptiveSamplesFor(scene.render) == 0;
  const InterruptGuard interrupts(stoppable);
  if (stoppable) plan.stop = &g_stopRequested;
  RenderResult result = renderScene(scene.job(), plan, report);
  if (result.stopped && result.sppDone == 0) {
    std::fprintf(stderr, "lvox: interrupted before any sample was finished: nothing written\n");
    return 130;
  }
  Image& image = result.image;
  report.memory["peak_rss"] = peakRssBytes();
  report.times["total"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  collectRankTimes(team, report);
  if (!team.isRoot()) return 0;  // the root writes the one image and report
  outputs.write(image, result.layers, report, flags.half, [&](OutputSet& set) {
    if (plan.reference) stageConvergenceCsv(set, flags.convergenceCsv, result.convergence);
    if (plan.cloudOut) writeCloud(flags.exportCloud, cloud, &set);
  });
  if (!flags.quiet) {
    printSummary(scene, report, outputs.exrPath());
    printRankTimes(report);
  }
  if (!result.stopped) return 0;
  const uint64_t next = flags.firstSample + static_cast<uint64_t>(result.sppDone);
  std::fprintf(stderr,
               "lvox: interrupted: %d of %d samples per pixel written; resume with "
               "--first-sample %llu --spp %d, then lvox merge\n",
               result.sppDone, plan.spp, static_cast<unsigned long long>(next),
               plan.spp - result.sppDone);
  return 130;
}

}  // namespace

void addRenderCommand(CLI::App& app, int& exitCode, Collective& team) {
  auto flags = std::make_shared<RenderFlags>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene to OUT.exr and OUT.png");
  cmd->add_option("scene", flags->scene, "Scene file (JSON)")->required();
  cmd->add_option("-o,--output", flags->output,
                  "Output EXR path (a PNG preview is written beside it)")
      ->required();
  cmd->add_option("--report", flags->report, "Write times, counts and memory as JSON");
  // Flags that set scene fields are checked by the scene loader, exactly like the fields;
  // without them the scene's field holds, else the setting's default (shown).
  const RenderSettings r;
  const VolumeSettings v;
  auto scene = [](const FlagField& f, const std::string& fallback) {
    return std::string(" (default: the scene's ") + f.section + "." + f.key +
           (fallback.empty() ? "" : ", else " + fallback) + ")";
  };
  cmd->add_option(flags::kMode.flag, flags->mode,
                  "Mode: " + modeNames() + scene(flags::kMode, std::string(modeName(r.mode))));
  cmd->add_option(flags::kSpp.flag, flags->spp,
                  "Samples per pixel" + scene(flags::kSpp, std::to_string(r.spp)));
  cmd->add_option(flags::kAdaptiveSpp.flag, flags->adaptiveSpp,
                  "Mean samples per pixel with adaptive samples: after --spp in every pixel, "
                  "more where the neighbours' samples disagree (0: none; auto: 3/2 of --spp "
                  "in the pcb modes)" +
                      scene(flags::kAdaptiveSpp, r.adaptiveSpp == RenderSettings::kAutoAdaptive
                                                     ? std::string("auto")
                                                     : std::to_string(r.adaptiveSpp)));
  cmd->add_option(
      flags::kMaxBounces.flag, flags->maxBounces,
      "Scattering events per path" + scene(flags::kMaxBounces, std::to_string(r.maxBounces)));
  cmd->add_option(flags::kSeed.flag, flags->seed,
                  "Random seed" + scene(flags::kSeed, std::to_string(r.seed)));
  cmd->add_option(flags::kThreads.flag, flags->threads,
                  "Worker threads, 0: all cores" + scene(flags::kThreads, "0"));
  cmd->add_option(flags::kMaxMemory.flag, flags->maxMemory,
                  "Memory budget, e.g. 4G or 512M; a render that would need more stops before "
                  "allocating it" +
                      scene(flags::kMaxMemory, "80 % of this machine's memory"));
  cmd->add_option(flags::kMaxEvaluations.flag, flags->maxEvaluations,
                  "Work budget in medium evaluations, e.g. 5e10; a render projected to need "
                  "more stops early" +
                      scene(flags::kMaxEvaluations, "1e6 per camera sample, at least 1e10"));
  cmd->add_option(flags::kWidth.flag, flags->width, "Image width" + scene(flags::kWidth, ""));
  cmd->add_option(flags::kHeight.flag, flags->height, "Image height" + scene(flags::kHeight, ""));
  cmd->add_option(flags::kSolver.flag, flags->solver,
                  "Volume solver: auto or one of " + rte::methodNames() + " (docs/solvers.md)" +
                      scene(flags::kSolver, "auto"));
  cmd->add_option(flags::kStep.flag, flags->step,
                  "Volume step in scene units (default: relative to the media)" +
                      scene(flags::kStep, v.step ? shortNumber(*v.step) : "relative"));
  cmd->add_option(
      flags::kTolerance.flag, flags->tolerance,
      "Tolerance of adaptive volume solvers" + scene(flags::kTolerance, shortNumber(v.tolerance)));
  cmd->add_option("--first-sample", flags->firstSample,
                  "Index of the first sample: render chunk [first, first+spp) of a longer run");
  cmd->add_option("--time-limit", flags->timeLimit,
                  "Seconds: render progressively (1, 2, 4, ... spp) until the budget or --spp")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--convergence", flags->convergenceReference,
                  "Reference EXR: record the error after 1, 2, 4, ... spp");
  cmd->add_option("--convergence-csv", flags->convergenceCsv, "Where the convergence CSV goes");
  cmd->add_option("--layers", flags->layers,
                  "AOV layers to write in the EXR beside the beauty: all, or a list of " +
                      namesOf(kLayerNames) + " (variance: mc only; docs/layers.md)");
  cmd->add_option("--export-cloud", flags->exportCloud,
                  "pcb, pcb-surfels: write the point cloud (surfels and lvoxels with position, "
                  "normal, radius, cached radiance) as CLOUD.ply or an OpenVDB PointDataGrid "
                  "CLOUD.vdb");
  cmd->add_option("--exposure", flags->exposure,
                  "Exposure of the PNG preview in stops (x 2^E before the tone map; the EXR "
                  "is never scaled)")
      ->capture_default_str();
  cmd->add_flag("--half", flags->half, "Write a half-float EXR (values above 65504 are clamped)");
  cmd->add_flag("-q,--quiet", flags->quiet, "No progress line and no summary line");
  cmd->callback([flags, &exitCode, &team]() { exitCode = runRender(*flags, team); });
}

}  // namespace lvox

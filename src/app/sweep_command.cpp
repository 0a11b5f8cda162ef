// `lvox sweep SCENE -o DIR`: renders a scene over methods x step sizes / tolerances (and
// Monte Carlo spp), measures each image against a reference, and writes DIR/sweep.csv
// and DIR/sweep.png (error against wall time and against medium evaluations, log-log,
// one curve per method, Pareto front marked). See docs/results.md, "speed against error".
// Each point's image and error map, the reference and an interactive report.html are kept
// beside them (sweep_images.h).
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "plot_sweep_script.h"
#include "src/app/commands.h"
#include "src/app/sweep_images.h"
#include "src/core/atomic_file.h"
#include "src/core/error.h"
#include "src/core/image_io.h"
#include "src/core/image_metrics.h"
#include "src/core/names.h"
#include "src/core/progress.h"
#include "src/render/renderer.h"
#include "src/scene/scene_loader.h"
#include "volume/rte/method.h"
#include "volume/volume_settings.h"

extern char** environ;

namespace lvox {
namespace {

namespace fs = std::filesystem;

struct SweepFlags {
  std::string scene;
  std::string outDir;
  std::vector<std::string> methods{"auto",  "euler",     "rk2",     "rk4",
                                   "ab4",   "trapezoid", "dopri5",  "bs23",
                                   "rkf45", "rectangle", "simpson", "gauss-kronrod"};
  std::vector<float> stepScales{4.0f, 2.0f, 1.0f, 0.5f, 0.25f};
  std::vector<float> tolerances{1e-1f, 1e-2f, 1e-3f, 1e-4f};
  std::vector<int> mcSpp;
  std::string reference;
  std::string referenceSolver = "rk4";
  float referenceStepScale = 1.0f / 16.0f;
  std::optional<std::string> mode;
  std::optional<int> width, height, spp, threads;
  bool plot = true;
  bool quiet = false;
};

// A method of the sweep: a volume solver (empty: auto) of the scene's mode, or mc, the
// path tracer at a number of samples per pixel.
struct SweepMethod {
  bool monteCarlo = false;
  std::optional<rte::Method> solver;
  std::string name() const {
    return monteCarlo ? std::string(modeName(Mode::kMc)) : std::string(solverName(solver));
  }
};

// "mc", "auto" or a solver name; throws InputError naming --methods.
SweepMethod parseSweepMethod(const std::string& name) {
  if (name == modeName(Mode::kMc)) return {true, std::nullopt};
  return {false, parseSolver(name, "--methods", "")};
}

// The accuracy parameter a sweep varies.
// A scene without a step sweeps the scale of its relative step (volume_integrator.step_scale).
enum class Knob { kStep, kStepScale, kTolerance, kSpp };
constexpr Named<Knob> kKnobNames[] = {{Knob::kStep, "step"},
                                      {Knob::kStepScale, "step_scale"},
                                      {Knob::kTolerance, "tol"},
                                      {Knob::kSpp, "spp"}};

// One render of the sweep: a method and the value of its accuracy parameter.
struct SweepPoint {
  SweepMethod method;
  Knob knob = Knob::kStep;
  double value = 0.0;
};

// The flags, parsed and checked before the scene is read.
struct SweepPlan {
  std::vector<SweepMethod> methods;
  std::optional<rte::Method> referenceSolver;
  std::vector<SettingOverride> overrides;
};

struct SweepRow {
  SweepPoint point;
  double seconds = 0.0;
  uint64_t mediumEvals = 0, steps = 0, rejected = 0, stabilityEvents = 0, capped = 0, invalid = 0;
  ImageError error;
  bool paretoTime = false, paretoEvals = false;
};

// Every point's parameter passes the check of the scene field it sets.
std::vector<SweepPoint> plan(const SweepFlags& f, const SweepPlan& sweep, const Scene& scene) {
  std::vector<SweepPoint> points;
  for (const SweepMethod& m : sweep.methods) {
    if (m.monteCarlo) {
      for (int spp : f.mcSpp) points.push_back({m, Knob::kSpp, static_cast<double>(spp)});
      continue;
    }
    if (!m.solver || rte::isAdaptive(*m.solver)) {
      for (float tol : f.tolerances) {
        checkRange(tol, kToleranceRange, "--tols", "");
        points.push_back({m, Knob::kTolerance, tol});
      }
    } else {
      for (float k : f.stepScales) {
        if (!scene.volume.step) {
          checkRange(scene.volume.stepScale * k, kStepScaleRange, "--step-scales", "");
          points.push_back({m, Knob::kStepScale, scene.volume.stepScale * k});
          continue;
        }
        checkRange(*scene.volume.step * k, kStepRange, "--step-scales", "");
        points.push_back({m, Knob::kStep, *scene.volume.step * k});
      }
    }
  }
  return points;
}

Scene configured(const Scene& base, const SweepPoint& p) {
  Scene s = base;
  if (p.method.monteCarlo) {
    s.render.mode = Mode::kMc;
    s.render.spp = static_cast<int>(p.value);
    return s;
  }
  s.volume.solver = p.method.solver;
  if (p.knob == Knob::kTolerance) s.volume.tolerance = static_cast<float>(p.value);
  if (p.knob == Knob::kStep) s.volume.step = static_cast<float>(p.value);
  if (p.knob == Knob::kStepScale) s.volume.stepScale = static_cast<float>(p.value);
  return s;
}

SweepRow renderPoint(const Scene& scene, const SweepPoint& p, const Image& reference,
                     Image& image) {
  Report report;
  const auto start = std::chrono::steady_clock::now();
  const Scene point = configured(scene, p);
  image = renderScene(point.job(), report);
  SweepRow row;
  row.point = p;
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Every evaluation the render made: camera rays, the point cloud's light cache and
  // direct mode's shadow transmittance cache (built with the method under test).
  row.mediumEvals = report.count("medium_evals") + report.count("cache_medium_evals") +
                    report.count("shadow_cache_medium_evals");
  row.steps = report.count("solver_steps");
  row.rejected = report.count("rejected_steps");
  row.stabilityEvents = report.count("stability_events");
  row.capped = report.count("capped_segments");
  row.invalid = report.count("invalid_samples");
  row.error = compareImages(image, reference, p.method.name(), "reference");
  return row;
}

// A row is on the front when no other row is at most as costly and strictly more accurate
// (or as accurate and strictly cheaper).
template <class Cost>
void markPareto(std::vector<SweepRow>& rows, Cost cost, bool SweepRow::*flag) {
  for (SweepRow& r : rows) {
    r.*flag = std::none_of(rows.begin(), rows.end(), [&](const SweepRow& o) {
      const bool noWorse = cost(o) <= cost(r) && o.error.deltaPercent <= r.error.deltaPercent;
      const bool better = cost(o) < cost(r) || o.error.deltaPercent < r.error.deltaPercent;
      return &o != &r && noWorse && better;
    });
  }
}

std::string csvText(const std::string& sceneName, Mode mode, const std::vector<SweepRow>& rows) {
  std::ostringstream csv;
  csv.precision(7);
  csv << "scene,mode,method,parameter,value,seconds,medium_evals,solver_steps,rejected_steps,"
         "stability_events,capped_segments,invalid_samples,delta_percent,relmse,rmse,psnr_db,"
         "pareto_time,pareto_evals\n";
  for (const SweepRow& r : rows)
    csv << sceneName << ',' << modeName(r.point.method.monteCarlo ? Mode::kMc : mode) << ','
        << r.point.method.name() << ',' << nameOf(r.point.knob, kKnobNames) << ',' << r.point.value
        << ',' << r.seconds << ',' << r.mediumEvals << ',' << r.steps << ',' << r.rejected << ','
        << r.stabilityEvents << ',' << r.capped << ',' << r.invalid << ',' << r.error.deltaPercent
        << ',' << r.error.relMse << ',' << r.error.rmse << ',' << r.error.psnrDb << ','
        << r.paretoTime << ',' << r.paretoEvals << '\n';
  return csv.str();
}

void writeText(const std::string& path, const std::string& text) {
  publishAtomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw std::runtime_error("cannot write " + tmp);
  });
}

// Runs the embedded plotting script with Debian's python3 + matplotlib (/usr/bin/python3,
// where python3-matplotlib installs, ahead of any other python3 on the PATH).
void plot(const std::string& csvPath, const std::string& pngPath, const std::string& title) {
  const fs::path script =
      fs::temp_directory_path() / ("lvox-plot-sweep-" + std::to_string(getpid()) + ".py");
  {
    std::ofstream out(script);
    out << kPlotSweepScript;
    if (!out) throw InputError(script.string(), "plot", "cannot write the plotting script");
  }
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::vector<std::string> args{python, script.string(), csvPath, pngPath, title};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  int status = -1;
  const int spawned = posix_spawnp(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ);
  if (spawned == 0) waitpid(pid, &status, 0);
  fs::remove(script);
  if (spawned != 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw InputError(pngPath, "plot",
                     "python3 with matplotlib failed (Debian: python3-matplotlib); the CSV is "
                     "written, --no-plot skips the plot");
}

Image referenceImage(const SweepFlags& f, const SweepPlan& sweep, const Scene& scene,
                     std::string& description, Collective& team) {
  const Camera& camera = scene.world.camera;
  if (!f.reference.empty()) {
    Image ref = readExr(f.reference);
    if (ref.width != camera.width || ref.height != camera.height)
      throw InputError(f.reference, "--reference",
                       "is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                           ", the sweep renders " + std::to_string(camera.width) + "x" +
                           std::to_string(camera.height));
    description = f.reference;
    return ref;
  }
  Scene fine = scene;
  fine.volume.solver = sweep.referenceSolver;
  fine.volume.tolerance = std::min(scene.volume.tolerance, 1e-6f);
  fine.volume.maxEvaluations = std::max(fine.volume.maxEvaluations, 10000000u);
  std::ostringstream d;
  d << solverName(sweep.referenceSolver);
  if (scene.volume.step) {
    fine.volume.step = *scene.volume.step * f.referenceStepScale;
    checkRange(*fine.volume.step, kStepRange, "--reference-step-scale", "");
    d << " at step " << *fine.volume.step;
  } else {
    fine.volume.stepScale = scene.volume.stepScale * f.referenceStepScale;
    checkRange(fine.volume.stepScale, kStepScaleRange, "--reference-step-scale", "");
    d << " at " << fine.volume.stepScale << " of the media's own step";
  }
  description = d.str();
  Report report;
  RenderPlan whole;
  whole.spp = fine.render.spp;
  whole.team = &team;  // split over the ranks like any render
  return renderScene(fine.job(), whole, report).image;
}

// A row's measured numbers, for the sum over ranks that brings every row to the root.
constexpr size_t kRowNumbers = 13;
void putRow(const SweepRow& r, double* v) {
  const ImageError& e = r.error;
  const double values[kRowNumbers] = {r.seconds,
                                      static_cast<double>(r.mediumEvals),
                                      static_cast<double>(r.steps),
                                      static_cast<double>(r.rejected),
                                      static_cast<double>(r.stabilityEvents),
                                      static_cast<double>(r.capped),
                                      static_cast<double>(r.invalid),
                                      e.deltaPercent,
                                      e.relMse,
                                      e.rmse,
                                      e.psnrDb,
                                      e.maxAbs,
                                      e.meanRatio};
  std::copy(values, values + kRowNumbers, v);
}
void getRow(const double* v, SweepRow& r) {
  const auto count = [](double x) { return static_cast<uint64_t>(std::llround(x)); };
  r.seconds = v[0];
  r.mediumEvals = count(v[1]);
  r.steps = count(v[2]);
  r.rejected = count(v[3]);
  r.stabilityEvents = count(v[4]);
  r.capped = count(v[5]);
  r.invalid = count(v[6]);
  r.error = ImageError{v[7], v[8], v[9], v[10], v[11], v[12]};
}

// Every rank renders the points it takes from the shared counter (one at a time: points
// differ a hundredfold in cost) and keeps their images; the rows then reach every rank.
// In one process this is the plain loop over the points.
std::vector<SweepRow> renderPoints(const SweepFlags& f, const Scene& scene,
                                   const std::vector<SweepPoint>& points, const Image& reference,
                                   const SweepKeeper& keeper, Collective& team) {
  std::vector<SweepRow> rows(points.size());
  std::vector<double> numbers(points.size() * kRowNumbers, 0.0);
  team.resetCounter();
  for (uint64_t i = team.take(1); i < points.size(); i = team.take(1)) {
    const SweepPoint& p = points[i];
    Image image;
    const SweepRow r = renderPoint(scene, p, reference, image);
    putRow(r, &numbers[i * kRowNumbers]);
    keeper.keepPoint(i, p.method.name(), std::string(nameOf(p.knob, kKnobNames)), p.value, image,
                     reference);
    if (!f.quiet)
      std::fprintf(
          stderr, "  %-16s %s %-9.4g %8.3f s %13llu evals  delta %.4f %%%s\n",
          p.method.name().c_str(), std::string(nameOf(p.knob, kKnobNames)).c_str(), p.value,
          r.seconds, static_cast<unsigned long long>(r.mediumEvals), r.error.deltaPercent,
          team.distributed() ? (" (rank " + std::to_string(team.rank()) + ")").c_str() : "");
  }
  team.sum(numbers);  // every row was rendered by exactly one rank
  for (size_t i = 0; i < points.size(); ++i) {
    rows[i].point = points[i];
    getRow(&numbers[i * kRowNumbers], rows[i]);
  }
  return rows;
}

// Parses every flag that names a method or sets a scene field, before the scene is read.
SweepPlan parseFlags(const SweepFlags& f) {
  SweepPlan sweep;
  for (const std::string& m : f.methods) {
    sweep.methods.push_back(parseSweepMethod(m));
    if (sweep.methods.back().monteCarlo && f.mcSpp.empty())
      throw InputError("--methods", "", "mc needs --mc-spp");
  }
  sweep.referenceSolver = parseSolver(f.referenceSolver, "--reference-solver", "");
  addOverride(sweep.overrides, flags::kMode, f.mode);
  addOverride(sweep.overrides, flags::kSpp, f.spp);
  addOverride(sweep.overrides, flags::kThreads, f.threads);
  addOverride(sweep.overrides, flags::kWidth, f.width);
  addOverride(sweep.overrides, flags::kHeight, f.height);
  return sweep;
}

int runSweep(const SweepFlags& f, Collective& team) {
  // Each point's phases on the progress line: on a terminal only, from the root.
  Progress::global().enable(!f.quiet && team.isRoot() && isatty(STDERR_FILENO) != 0);
  const SweepPlan sweep = parseFlags(f);
  Scene scene = loadScene(f.scene, sweep.overrides);
  if (scene.render.mode == Mode::kMc)
    throw InputError(f.mode ? flags::kMode.flag : f.scene, f.mode ? "" : "render.mode",
                     "the sweep compares solvers: use direct, pcb or pcb-surfels");
  if (!fs::is_directory(f.outDir))
    throw InputError(f.outDir, "--output", "is not an existing directory");
  const std::vector<SweepPoint> points = plan(f, sweep, scene);
  const std::string csvPath = (fs::path(f.outDir) / "sweep.csv").string();
  const std::string pngPath = (fs::path(f.outDir) / "sweep.png").string();
  checkOutputPath(csvPath, "--output", scene.inputFiles);
  const SweepKeeper keeper(f.outDir, f.reference, scene.inputFiles);

  std::string refDescription;
  const Image reference = referenceImage(f, sweep, scene, refDescription, team);
  if (team.isRoot()) keeper.start(reference);
  team.barrier();  // start() clears old point images: no rank keeps one before
  const std::string mode(modeName(scene.render.mode));
  if (!f.quiet && team.isRoot())
    std::fprintf(
        stderr, "lvox sweep: %zu renders of %s (%s mode) against %s%s\n", points.size(),
        fs::path(f.scene).filename().c_str(), mode.c_str(), refDescription.c_str(),
        team.distributed() ? (", over " + std::to_string(team.size()) + " ranks").c_str() : "");
  std::vector<SweepRow> rows = renderPoints(f, scene, points, reference, keeper, team);
  if (!team.isRoot()) return 0;  // the root writes the CSV, the plot and the report
  markPareto(
      rows, [](const SweepRow& r) { return r.seconds; }, &SweepRow::paretoTime);
  markPareto(
      rows, [](const SweepRow& r) { return static_cast<double>(r.mediumEvals); },
      &SweepRow::paretoEvals);
  const std::string name = fs::path(f.scene).stem().string();
  writeText(csvPath, csvText(name, scene.render.mode, rows));
  const std::string title = name + " (" + mode + ", " + std::to_string(scene.world.camera.width) +
                            "x" + std::to_string(scene.world.camera.height) + ", " +
                            std::to_string(scene.render.spp) + " spp) vs " + refDescription;
  if (f.plot) plot(csvPath, pngPath, title);
  std::vector<std::pair<double, size_t>> front;
  for (size_t i = 0; i < rows.size(); ++i)
    if (rows[i].paretoTime) front.emplace_back(rows[i].seconds, i);
  keeper.publishReport(title, front);
  if (!f.quiet) std::fprintf(stderr, "lvox sweep: wrote %s\n", csvPath.c_str());
  return 0;
}

}  // namespace

void addSweepCommand(CLI::App& app, int& exitCode, Collective& team) {
  auto f = std::make_shared<SweepFlags>();
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Render a scene over solvers x steps/tolerances; CSV and plots of error vs cost");
  cmd->add_option("scene", f->scene, "Scene file (JSON)")->required();
  cmd->add_option(
         "-o,--output", f->outDir,
         "Existing directory for sweep.csv, sweep.png, report.html, reference.exr and points/")
      ->required();
  cmd->add_option("--methods", f->methods,
                  "Comma-separated: auto, any solver name, mc (Monte Carlo, with --mc-spp)")
      ->delimiter(',');
  cmd->add_option(
         "--step-scales", f->stepScales,
         "Fixed-step methods: multiples of the scene's step (of the media's own step when the "
         "scene gives none)")
      ->delimiter(',');
  cmd->add_option("--tols", f->tolerances, "Adaptive methods and auto: tolerances")->delimiter(',');
  cmd->add_option("--mc-spp", f->mcSpp, "Monte Carlo: samples per pixel")
      ->delimiter(',')
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--reference", f->reference,
                  "Reference EXR (e.g. a converged MC render); default: a fine render")
      ->check(CLI::ExistingFile);
  cmd->add_option("--reference-solver", f->referenceSolver, "Solver of the fine reference");
  cmd->add_option("--reference-step-scale", f->referenceStepScale,
                  "Step of the fine reference as a multiple of the scene's step");
  cmd->add_option(flags::kMode.flag, f->mode, "direct | pcb | pcb-surfels");
  cmd->add_option(flags::kWidth.flag, f->width, "Image width");
  cmd->add_option(flags::kHeight.flag, f->height, "Image height");
  cmd->add_option(flags::kSpp.flag, f->spp, "Samples per pixel of the solver renders");
  cmd->add_option(flags::kThreads.flag, f->threads, "Worker threads (0: all cores)");
  cmd->add_flag(
      "!--no-plot", f->plot,
      "No matplotlib plot (sweep.png); the CSV, images and report.html are still written");
  cmd->add_flag("-q,--quiet", f->quiet, "No progress lines");
  cmd->callback([f, &exitCode, &team]() { exitCode = runSweep(*f, team); });
}

}  // namespace lvox

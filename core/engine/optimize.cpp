#include "core/engine/optimize.h"

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/base/errors.h"
#include "core/extract/quads.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/retry.h"

namespace qs {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string number(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

void require(bool ok, const std::string& setting, double value, const std::string& rule) {
  if (!ok)
    throw InvalidInputError("optimize setting " + setting + " = " + number(value) + ": must be " +
                            rule);
}

// Why a retry starts, for the user.
std::string retry_reason(const NodeOptResult& first) {
  if (first.foldovers_final > 0)
    return std::to_string(first.foldovers_final) + " fold-over(s) remain";
  if (first.untangled) return "only the untangling removed the fold-overs";
  if (first.initial_reverted) return "the fold-over removal fell back to the initial state";
  return "the fold-over removal fell back to an earlier state";
}

// A fixed-node Pipeline at (\p mesh, \p layout) whose orientation-constrained solve polls
// \p observer (kept in its options: only its solves use it).
std::shared_ptr<Pipeline> fixed_pipeline(const TriMesh& mesh, const Layout& layout,
                                         PipelineOptions options, Observer* observer) {
  options.param.orientation.observer = observer;
  return std::make_shared<Pipeline>(mesh, layout, std::move(options));
}

}  // namespace

bool symmetric(const OptimizeSettings& s) {
  return s.nodes.symmetry || s.nodes.symmetry_plane;
}

void validate_settings(const OptimizeSettings& s) {
  require(std::isfinite(s.field.sharp_angle_deg) && s.field.sharp_angle_deg > 0 &&
              s.field.sharp_angle_deg <= 180,
          "field.sharp_angle_deg", s.field.sharp_angle_deg, "in (0, 180]");
  require(s.field.max_cluster_faces >= 0, "field.max_cluster_faces", s.field.max_cluster_faces,
          "≥ 0");
  require(std::isfinite(s.param.anisotropy) && s.param.anisotropy >= 1, "param.anisotropy",
          s.param.anisotropy, "finite and ≥ 1");
  require(s.nodes.steps >= 0, "nodes.steps", s.nodes.steps, "≥ 0");
  require(std::isfinite(s.nodes.alpha) && s.nodes.alpha > 0 && s.nodes.alpha <= 1, "nodes.alpha",
          s.nodes.alpha, "in (0, 1]");
  require(std::isfinite(s.nodes.time_limit_s) && s.nodes.time_limit_s >= 0, "nodes.time_limit_s",
          s.nodes.time_limit_s, "finite and ≥ 0");
  require(s.nodes.threads >= 1, "nodes.threads", s.nodes.threads, "≥ 1");
  require(std::isfinite(s.sizes.quad_size) && s.sizes.quad_size >= 0, "sizes.quad_size",
          s.sizes.quad_size, "finite and ≥ 0");
  require(s.sizes.quad_count >= 0, "sizes.quad_count", s.sizes.quad_count, "≥ 0");
  if (s.sizes.integer && !(s.sizes.quad_size > 0 || s.sizes.quad_count > 0))
    throw InvalidInputError("integer sizes need a quad size or a quad count");
  if (s.nodes.separate_crowded && (!s.nodes.enabled || s.nodes.method == NodeMethod::kDiscrete))
    throw InvalidInputError(
        "separating crowded nodes applies to the continuous node optimization only");
  if (s.nodes.time_limit_s > 0 && !s.nodes.enabled)
    throw InvalidInputError("a time limit applies to the node optimization only");
  if (symmetric(s)) {
    if (!s.nodes.enabled || s.nodes.method == NodeMethod::kDiscrete)
      throw InvalidInputError(
          "symmetric optimization applies to the continuous node optimization only");
    if (s.nodes.separate_crowded)
      throw InvalidInputError(
          "separating crowded nodes moves single nodes: not with symmetric optimization");
  }
  if (s.nodes.symmetry_plane) {
    const MirrorPlane& p = *s.nodes.symmetry_plane;
    const double length = p.normal.norm();
    require(std::isfinite(length) && std::abs(length - 1) <= 1e-6, "nodes.symmetry_plane.normal",
            length, "of length 1");
    require(std::isfinite(p.offset), "nodes.symmetry_plane.offset", p.offset, "finite");
  }
}

PipelineOptions pipeline_options(const OptimizeSettings& s) {
  PipelineOptions o;
  o.field.constraints.curvature = s.field.align;
  o.field.constraints.sharp_angle_deg = s.field.sharp_angle_deg;
  o.field.max_cluster_faces = s.field.max_cluster_faces;
  if (s.field.wrap_free_holes) o.field.free_loops = FreeLoopTurning::kWrap;
  o.param.anisotropy = s.param.anisotropy;
  o.param.sizing.enabled = s.param.sizing.value_or(false);
  // The node optimizer's constrained solves take these too (enabling them itself).
  o.param.orientation.sector_frame = s.folds.sectors;
  o.param.orientation.untangle = s.folds.untangle;
  if (!s.nodes.enabled && s.folds.remove.value_or(false)) o.param.orientation.enabled = true;
  return o;
}

NodeOptOptions node_options(const OptimizeSettings& s) {
  NodeOptOptions no;
  no.descent.max_steps = s.nodes.steps;
  no.descent.alpha = s.nodes.alpha;
  no.descent.gradient =
      s.nodes.method == NodeMethod::kExact ? GradientMethod::Exact : GradientMethod::Estimator;
  no.moves.slide_on_curves = s.nodes.slide_on_curves;
  no.moves.sharp_edges_as_curves = s.nodes.keep_sharp_edges;
  no.moves.keep_nodes_apart = s.nodes.keep_apart.value_or(false);
  no.moves.separate_crowded_nodes = s.nodes.separate_crowded;
  // The sector frame and the untangling come with pipeline_options().
  no.folds.orientation = s.folds.remove.value_or(true);
  no.run.threads = s.nodes.threads;
  // Integer sizes put nodes exactly on shared iso-lines: fresh trial Pipelines there
  // (NodeOptOptions::Run::reuse_field).
  if (s.sizes.integer) no.run.reuse_field = false;
  return no;
}

struct OptimizeRun::Impl {
  // The stages of the policy, in order; a stage without its run is skipped.
  enum class Stage { kFirst, kApart, kSizing, kInteger, kDone };

  OptimizeSettings settings;
  TriMesh input_mesh;  // the start of the first run and of the retries
  Layout input_layout;
  PipelineOptions input_options;
  PipelineOptions options;  // of the kept run's final solve (base of the final solve)
  NodeOptOptions base_node_options;
  std::optional<Clock::time_point> deadline;
  Stage stage = Stage::kFirst;

  // The node optimization going on, its solver options and its keep-apart choice.
  std::unique_ptr<NodeOptimizer> current;
  PipelineOptions current_options;
  bool current_apart = false;
  Clock::time_point current_start;
  // The discrete baseline runs as one unit from start_mesh and start_layout.
  bool discrete_pending = false;
  TriMesh start_mesh;
  Layout start_layout;

  std::optional<NodeOptResult> kept;  // the run kept so far
  bool keep_apart = false;
  std::shared_ptr<Pipeline> fixed;  // fixed nodes: the one solve
  std::vector<char> pins, arc_pins;
  OptimizeResult result;
  std::vector<std::string> notes;
  int runs = 0;
  const std::vector<StepReport> no_reports{};  // reports() of a run without node optimization

  bool moving() const { return settings.nodes.enabled; }
  bool discrete() const { return settings.nodes.method == NodeMethod::kDiscrete; }

  std::function<bool()> stop() const {
    if (!deadline) return {};
    const Clock::time_point end = *deadline;
    return [end] { return Clock::now() >= end; };
  }

  void apply_pins() {
    if (!current || pins.empty()) return;
    current->set_pinned(pins, arc_pins);
  }

  void start(const TriMesh& mesh, const Layout& layout, const PipelineOptions& po, bool apart,
             Observer* observer) {
    current_options = po;
    current_apart = apart;
    current_start = Clock::now();
    ++runs;
    if (discrete()) {
      discrete_pending = true;
      start_mesh = mesh;
      start_layout = layout;
      return;
    }
    NodeOptOptions no = base_node_options;
    no.moves.keep_nodes_apart = apart;
    no.run.stop = stop();
    current = std::make_unique<NodeOptimizer>(mesh, layout, po, no, observer);
    apply_pins();
  }

  void adopt(NodeOptResult r, const PipelineOptions& po, bool apart) {
    options = po;
    options.param.face_weights = r.face_weights;
    if (r.orientation_constraints) options.param.orientation = r.orientation_options;
    keep_apart = apart;
    kept = std::move(r);
  }

  // The outcome of the run that just ended (\p r), by the stage it belongs to.
  void end_run(NodeOptResult r) {
    result.node_time_s += seconds_since(current_start);
    result.time_limited |= r.stopped;
    if (r.crowded_nodes > 0)
      notes.push_back(std::to_string(r.separated_nodes.size()) + " of " +
                      std::to_string(r.crowded_nodes) +
                      " crowded node(s) moved apart before the node optimization");
    if (stage == Stage::kFirst || stage == Stage::kInteger) {
      adopt(std::move(r), current_options, current_apart);
      return;
    }
    const NodeOptResult& first = *kept;
    RetryRecord rec;
    rec.with = stage == Stage::kApart ? "nodes kept apart" : "the sizing field";
    rec.used = stage == Stage::kApart ? keep_apart_retry_is_better(r, first)
                                      : sizing_retry_is_better(r, first);
    rec.foldovers_without = first.foldovers_final;
    rec.foldovers_with = r.foldovers_final;
    rec.E_without = first.E_final;
    rec.E_with = r.E_final;
    rec.untangled_without = first.untangled;
    rec.untangled_with = r.untangled;
    rec.fell_back_without = fell_back(first);
    rec.initial_without = first.initial_reverted;
    rec.initial_with = r.initial_reverted;
    rec.time_s = seconds_since(current_start);
    notes.push_back("with " + rec.with + " " + std::to_string(r.foldovers_final) +
                    " fold-over(s) remain at E " + number(r.E_final) + " (" +
                    std::to_string(first.foldovers_final) + " at E " + number(first.E_final) +
                    " without): " + (rec.used ? "using it" : "keeping the run without it"));
    (stage == Stage::kApart ? result.keep_apart_retry : result.sizing_retry) = rec;
    if (rec.used) adopt(std::move(r), current_options, current_apart);
  }

  // Rounds the arc lengths of the kept state (or the fixed-node solve) to multiples of the quad
  // size and returns the options with those lengths.
  PipelineOptions integer_options(const TriMesh& mesh, const Layout& layout,
                                  std::shared_ptr<Pipeline> relaxed) {
    if (!relaxed) relaxed = std::make_shared<Pipeline>(mesh, layout, options);
    if (!relaxed->parameterization()) relaxed->compute_parameterization();
    result.E_relaxed =
        unweighted_energy(relaxed->mesh(), relaxed->geometry(), relaxed->field()->theta,
                          *relaxed->parameterization(), options.param);
    const double q = settings.sizes.quad_size > 0
                         ? settings.sizes.quad_size
                         : quad_size_for_count(relaxed->topology(), relaxed->extract(),
                                               settings.sizes.quad_count);
    result.integer = round_arc_lengths(relaxed->param_solver()->arc_lengths(), q);
    notes.push_back("integer sizes with quad size " + number(q) + ": " +
                    std::to_string(result.integer->lengths.size()) +
                    " arc lengths rounded (largest change " + number(result.integer->max_change) +
                    "), relaxed E = " + number(result.E_relaxed));
    PipelineOptions fixed_lengths = options;
    fixed_lengths.param.arc_lengths = result.integer->lengths;
    fixed_lengths.param.face_weights.clear();
    // The node optimizer's constrained solve is not carried over (the input's orientation
    // options, not enabled, are); fixed nodes keep theirs.
    if (moving()) fixed_lengths.param.orientation = input_options.param.orientation;
    return fixed_lengths;
  }

  // Starts the next run the policy asks for after the one that just ended; false: none.
  bool next_run(Observer* observer) {
    const bool removes_folds = settings.folds.remove.value_or(true) && !discrete();
    if (stage == Stage::kFirst) {
      stage = Stage::kApart;
      if (removes_folds && !settings.nodes.keep_apart && wants_keep_apart_retry(*kept)) {
        notes.push_back(retry_reason(*kept) +
                        "; optimizing again from the input with nodes kept apart (setting "
                        "'keep nodes apart' either way decides this up front)");
        start(input_mesh, input_layout, input_options, true, observer);
        return true;
      }
    }
    if (stage == Stage::kApart) {
      stage = Stage::kSizing;
      if (removes_folds && !settings.param.sizing && wants_sizing_retry(*kept)) {
        notes.push_back(retry_reason(*kept) +
                        "; optimizing again from the input with the sizing field (setting "
                        "'sizing field' either way decides this up front)");
        PipelineOptions sized = input_options;
        sized.param.sizing.enabled = true;
        start(input_mesh, input_layout, sized, keep_apart, observer);
        return true;
      }
    }
    if (stage == Stage::kSizing) {
      stage = Stage::kInteger;
      if (settings.sizes.integer) {
        std::shared_ptr<Pipeline> relaxed;
        if (kept->pipeline && kept->face_weights.empty()) relaxed = kept->pipeline;
        const PipelineOptions fixed_lengths =
            integer_options(kept->mesh, kept->layout, std::move(relaxed));
        const TriMesh mesh = kept->mesh;
        const Layout layout = kept->layout;
        result.relaxed = std::move(kept);
        kept.reset();
        options = fixed_lengths;
        start(mesh, layout, fixed_lengths, keep_apart, observer);
        return true;
      }
    }
    stage = Stage::kDone;
    return false;
  }

  // Ends the node optimization going on (fold-over removal) or the pending discrete run.
  void end_current(Observer* observer) {
    if (current) {
      NodeOptResult r = current->finish(observer);
      current.reset();
      end_run(std::move(r));
    } else if (discrete_pending) {
      discrete_pending = false;
      DiscreteOptions d;
      d.max_steps = settings.nodes.steps;
      d.stop = stop();
      end_run(relocate_nodes_discrete(start_mesh, start_layout, current_options, d, observer));
    }
  }
};

OptimizeRun::OptimizeRun(TriMesh mesh, Layout layout, const OptimizeSettings& settings,
                         Observer* observer)
    : impl_(std::make_unique<Impl>()) {
  validate_settings(settings);
  Impl& m = *impl_;
  m.settings = settings;
  m.input_options = pipeline_options(settings);
  m.options = m.input_options;
  m.base_node_options = node_options(settings);
  m.input_mesh = std::move(mesh);
  m.input_layout = std::move(layout);
  if (symmetric(settings)) {
    // The plane and the pairs once, on the input: every run (retries, the integer run) keeps
    // them, and a layout that is not symmetric is refused here, naming its first unpaired node.
    MirrorPlane plane;
    if (settings.nodes.symmetry_plane) {
      plane = *settings.nodes.symmetry_plane;
    } else {
      const ClosestPointTree tree(m.input_mesh);
      plane = mirror_plane(m.input_mesh, tree, *settings.nodes.symmetry).plane;
    }
    m.base_node_options.moves.symmetry = make_node_symmetry(m.input_mesh, m.input_layout, plane);
    m.result.symmetry = m.base_node_options.moves.symmetry;
  }
  if (!m.moving()) {
    m.stage = Impl::Stage::kDone;  // the one solve is made by pipeline() or the caller
    return;
  }
  if (settings.nodes.time_limit_s > 0)
    m.deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(settings.nodes.time_limit_s));
  m.start(m.input_mesh, m.input_layout, m.input_options, settings.nodes.keep_apart.value_or(false),
          observer);
}

OptimizeRun::~OptimizeRun() = default;

bool OptimizeRun::step(Observer* observer) {
  Impl& m = *impl_;
  if (m.stage == Impl::Stage::kDone) return false;
  if (m.current && m.current->step(observer)) return true;
  m.end_current(observer);
  return m.next_run(observer);
}

void OptimizeRun::set_pinned(const std::vector<char>& nodes, const std::vector<char>& arcs) {
  Impl& m = *impl_;
  if (nodes.size() != m.input_layout.nodes.size() ||
      (!arcs.empty() && arcs.size() != m.input_layout.arcs.size()))
    throw std::invalid_argument("OptimizeRun::set_pinned: one flag per node and per arc");
  m.pins = nodes;
  if (!arcs.empty()) m.arc_pins = arcs;
  m.apply_pins();
}

const TriMesh& OptimizeRun::mesh() const {
  const Impl& m = *impl_;
  if (m.current) return m.current->mesh();
  if (m.discrete_pending) return m.start_mesh;
  if (m.fixed) return m.fixed->mesh();
  return m.kept ? m.kept->mesh : m.input_mesh;
}

const Layout& OptimizeRun::layout() const {
  const Impl& m = *impl_;
  if (m.current) return m.current->layout();
  if (m.discrete_pending) return m.start_layout;
  if (m.fixed) return m.fixed->layout();
  return m.kept ? m.kept->layout : m.input_layout;
}

std::shared_ptr<Pipeline> OptimizeRun::pipeline(Observer* observer) {
  Impl& m = *impl_;
  if (m.current) return m.current->pipeline(observer);
  if (!m.moving()) {
    if (!m.fixed) m.fixed = fixed_pipeline(m.input_mesh, m.input_layout, m.options, observer);
    if (!m.fixed->parameterization()) m.fixed->compute_parameterization();
    return m.fixed;
  }
  if (m.kept && m.kept->pipeline) return m.kept->pipeline;
  auto p = std::make_shared<Pipeline>(mesh(), layout(), m.options);
  p->compute_parameterization();
  return p;
}

const std::vector<StepReport>& OptimizeRun::reports() const {
  const Impl& m = *impl_;
  if (m.current) return m.current->reports();
  if (m.kept) return m.kept->reports;
  return m.no_reports;
}

int OptimizeRun::runs() const {
  return impl_->runs;
}

std::vector<std::string> OptimizeRun::take_notes() {
  return std::exchange(impl_->notes, {});
}

OptimizeResult OptimizeRun::finish(Observer* observer) {
  Impl& m = *impl_;
  if (m.stage != Impl::Stage::kDone) {
    m.end_current(observer);
    m.stage = Impl::Stage::kDone;
  }
  OptimizeResult& r = m.result;
  if (!m.moving()) {
    if (m.settings.sizes.integer) {
      pipeline(observer);
      const PipelineOptions fixed_lengths =
          m.integer_options(m.input_mesh, m.input_layout, m.fixed);
      m.options = fixed_lengths;
      m.fixed.reset();
    }
    if (!m.fixed) m.fixed = fixed_pipeline(m.input_mesh, m.input_layout, m.options, observer);
    r.pipeline = m.fixed;
  } else {
    NodeOptResult& kept = *m.kept;
    if (kept.pipeline && kept.face_weights.empty())
      r.pipeline = kept.pipeline;
    else {
      r.pipeline = std::make_shared<Pipeline>(kept.mesh, kept.layout, m.options);
      if (observer && observer->should_cancel()) throw Cancelled();
      r.pipeline->compute_parameterization();
    }
    r.keep_nodes_apart = m.keep_apart;
    r.nodes = std::move(m.kept);
  }
  r.options = m.options;
  return std::move(r);
}

OptimizeResult optimize(TriMesh mesh, Layout layout, const OptimizeSettings& settings,
                        Observer* observer, std::vector<std::string>* notes) {
  OptimizeRun run(std::move(mesh), std::move(layout), settings, observer);
  const auto collect = [&] {
    if (!notes) return;
    for (auto& n : run.take_notes()) notes->push_back(std::move(n));
  };
  while (run.step(observer)) collect();
  OptimizeResult r = run.finish(observer);
  collect();
  return r;
}

}  // namespace qs

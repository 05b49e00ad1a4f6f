#include "request_generator.h"

#include <fmt/format.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/stubs/logging.h>

#include <stdexcept>

#include "base_requests.h"
#include "message_mutator.h"
#include "seep/v1/job_service.pb.h"

namespace seep::fuzz {
namespace {

using google::protobuf::Message;

FuzzRequest Wrap(const std::string& method, std::unique_ptr<Message> message, std::string what) {
  FuzzRequest request;
  request.method = method;
  request.type = SeepMethod(method).input_type();
  request.streaming = SeepMethod(method).server_streaming();
  request.bytes = message->SerializeAsString();
  if (const auto* id = request.type->FindFieldByName("id"); id != nullptr) {
    request.id = message->GetReflection()->GetString(*message, id);
  } else if (const auto* job_id = request.type->FindFieldByName("job_id"); job_id != nullptr) {
    request.id = message->GetReflection()->GetString(*message, job_id);
  }
  request.message = std::move(message);
  request.what = std::move(what);
  return request;
}

// Mutates `message` once to a few times; the mutations, joined.
std::string Mutate(Message& message, const std::string& root, FuzzRandom& random) {
  const int count = random.Chance(0.6) ? 1 : random.Chance(0.75) ? random.Int(2, 3) : 8;
  std::string what;
  for (int i = 0; i < count; ++i) {
    what += (i ? "; " : "") + MutateOnce(message, root, random);
  }
  return what;
}

std::string OddId(FuzzRandom& random, const FuzzContext& context) {
  switch (random.Below(12)) {
    case 0:
      return "";
    case 1:
      return "j-0123456789abcdef";
    case 2:
      return std::string(64, 'j');
    case 3:
      return std::string(65, 'j');
    case 4:
      return std::string(static_cast<std::size_t>(random.Int(1000, 20'000)), 'j');
    case 5:
      return "j-\n\r\x1b[2J";
    case 6:
      return "'; DROP TABLE jobs; --";
    case 7:
      return "%_%";
    case 8:
      return std::string("j-\0abc", 6);
    case 9:
      return context.sweep_ids.empty() ? "s-0" : random.Pick(context.sweep_ids);  // wrong kind
    case 10:
      return context.job_ids.empty() ? "j-" : random.Pick(context.job_ids) + "x";
    default:
      return "../checkpoints";
  }
}

std::string JobId(FuzzRandom& random, const FuzzContext& context) {
  if (!context.job_ids.empty() && random.Chance(0.7)) return random.Pick(context.job_ids);
  return OddId(random, context);
}

std::string SweepId(FuzzRandom& random, const FuzzContext& context) {
  if (!context.sweep_ids.empty() && random.Chance(0.7)) return random.Pick(context.sweep_ids);
  if (!context.job_ids.empty() && random.Chance(0.2)) return random.Pick(context.job_ids);
  return OddId(random, context);
}

std::string RequestId(FuzzRandom& random, const FuzzContext& context) {
  if (!context.request_ids.empty() && random.Chance(0.3)) return random.Pick(context.request_ids);
  return fmt::format("fuzz-{:016x}", random.Next());
}

FuzzRequest SubmitScene(FuzzRandom& random, const FuzzContext& context, bool mutate) {
  const BaseScene& base = random.Pick(BaseScenes());
  auto request = std::make_unique<v1::SubmitJobRequest>();
  *request->mutable_scene() = base.scene;
  if (random.Chance(0.3)) request->set_request_id(RequestId(random, context));
  if (random.Chance(0.2)) (*request->mutable_labels())["fuzz"] = "yes";
  request->set_priority(random.Int(-3, 3));
  std::string what = "SubmitJob " + base.name;
  if (mutate) {
    // Mostly inside the scene; sometimes anywhere in the request.
    what += ": " + (random.Chance(0.8) ? Mutate(*request->mutable_scene(), "scene", random)
                                       : Mutate(*request, "", random));
  }
  return Wrap("SubmitJob", std::move(request), what);
}

FuzzRequest SubmitCalibration(FuzzRandom& random, const FuzzContext& context) {
  auto request = std::make_unique<v1::SubmitJobRequest>();
  *request->mutable_calibration() = BaseCalibration();
  std::string what = "SubmitJob calibration";
  if (random.Chance(0.2)) {
    // The packing of an earlier job (of any kind, in any state), or of an odd id.
    request->mutable_calibration()->mutable_scene()->mutable_packing()->clear_source();
    request->mutable_calibration()->set_from_job_id(JobId(random, context));
    what += " from " + request->calibration().from_job_id().substr(0, 40);
  }
  if (random.Chance(0.85)) {
    what += ": " + Mutate(*request->mutable_calibration(), "calibration", random);
  }
  return Wrap("SubmitJob", std::move(request), what);
}

FuzzRequest SubmitFork(FuzzRandom& random, const FuzzContext& context) {
  auto request = std::make_unique<v1::SubmitJobRequest>();
  std::string what = "SubmitJob fork";
  if (!context.staged_jobs.empty() && random.Chance(0.8)) {
    const auto& [parent, scene] = random.Pick(context.staged_jobs);
    request->set_from_job_id(parent);
    *request->mutable_scene() = scene;
    // A finished parent's fork needs a stage more.
    v1::Stage* more = request->mutable_scene()->add_stages();
    more->set_name("fork");
    more->add_end()->set_steps(10);
    what += " of " + parent;
  } else {
    request->set_from_job_id(JobId(random, context));
    *request->mutable_scene() = random.Pick(BaseScenes()).scene;
    what += " of " + request->from_job_id().substr(0, 40);
  }
  if (random.Chance(0.4)) request->set_from_step(random.Chance(0.5) ? 20 : random.Next());
  if (random.Chance(0.6)) what += ": " + Mutate(*request, "", random);
  return Wrap("SubmitJob", std::move(request), what);
}

// Sweep axes on paths that exist, do not, or lead somewhere odd.
const std::vector<std::string>& SweepPaths() {
  static const std::vector<std::string> paths = {"boundary.inlet_pressure_pa",
                                                 "packing.lattice.columns",
                                                 "packing.lattice.kind",
                                                 "solver.kind",
                                                 "name",
                                                 "effects[0].contacts.density_kg_m3",
                                                 "effects[99].flow.every_steps",
                                                 "stages[0].end[0].steps",
                                                 "packing.random.seed",
                                                 "aperture",
                                                 "boundary.regions[0].name",
                                                 "",
                                                 "boundary..axis",
                                                 "boundary.axis[0]",
                                                 "fluid.viscosity_pa_s.x"};
  return paths;
}

FuzzRequest SubmitSweep(FuzzRandom& random, const FuzzContext& context) {
  auto request = std::make_unique<v1::SubmitSweepRequest>();
  *request->mutable_sweep() = BaseSweep();
  if (random.Chance(0.3)) request->set_request_id(RequestId(random, context));
  std::string what = "SubmitSweep";
  switch (random.Below(5)) {
    case 0: {  // an axis on an odd path, with odd values of every kind
      v1::SweepAxis* axis = request->mutable_sweep()->add_axes();
      axis->set_path(random.Pick(SweepPaths()));
      if (random.Chance(0.6)) axis->add_numbers(OddDouble(1.0, random));
      if (random.Chance(0.3)) axis->add_texts(random.Chance(0.5) ? "SOLVER_KIND_STEADY" : "x");
      if (random.Chance(0.2)) axis->add_flags(true);
      what += " axis " + axis->path();
      break;
    }
    case 1: {  // replicates: an odd count or seed list on an odd seed path
      v1::SweepReplicates* replicates = request->mutable_sweep()->mutable_replicates();
      replicates->set_seed_path(random.Chance(0.7) ? "packing.lattice.columns"
                                                   : random.Pick(SweepPaths()));
      const std::vector<std::uint32_t> counts = {0, 1, 2, 3, 10'001, 100'000'000, 4'294'967'295u};
      replicates->set_count(random.Pick(counts));
      if (random.Chance(0.3)) replicates->mutable_seeds()->Resize(random.Int(1, 200'000), 7);
      what += fmt::format(" replicates {} count {} seeds {}", replicates->seed_path(),
                          replicates->count(), replicates->seeds_size());
      break;
    }
    case 2:
      // Axes of unequal length: refused when zipped, four points as a product.
      request->mutable_sweep()->mutable_axes(0)->add_numbers(3e-3);
      if (random.Chance(0.5)) request->mutable_sweep()->set_combine(v1::SWEEP_COMBINE_PRODUCT);
      what += fmt::format(" uneven axes, {}",
                          v1::SweepCombine_Name(request->mutable_sweep()->combine()));
      break;
    default:
      break;
  }
  what += ": " + Mutate(*request, "", random);
  return Wrap("SubmitSweep", std::move(request), what);
}

template <typename Request>
FuzzRequest IdCall(const std::string& method, const std::string& id) {
  auto request = std::make_unique<Request>();
  request->set_id(id);
  return Wrap(method, std::move(request), fmt::format("{} {}", method, id.substr(0, 40)));
}

FuzzRequest JobCall(FuzzRandom& random, const FuzzContext& context) {
  const std::string id = JobId(random, context);
  switch (random.Below(9)) {
    case 0:
      return IdCall<v1::GetJobRequest>("GetJob", id);
    case 1:
      return IdCall<v1::CancelJobRequest>("CancelJob", id);
    case 2:
      return IdCall<v1::ResumeJobRequest>("ResumeJob", id);
    case 3:
      return IdCall<v1::GetResultRequest>("GetResult", id);
    case 4:
      return IdCall<v1::DeleteJobRequest>("DeleteJob", id);
    case 5:
      return IdCall<v1::WatchJobRequest>("WatchJob", id);
    case 6: {
      auto request = std::make_unique<v1::ListJobEventsRequest>();
      request->set_id(id);
      request->set_page_size(static_cast<std::uint32_t>(
          random.Pick(std::vector<std::uint64_t>{0, 1, 1000, 1001, 4'294'967'295u})));
      std::string what = "ListJobEvents";
      if (random.Chance(0.4)) what += ": " + Mutate(*request, "", random);
      return Wrap("ListJobEvents", std::move(request), what);
    }
    default: {
      auto request = std::make_unique<v1::GetJobFieldsRequest>();
      request->set_job_id(id);
      request->set_step(
          random.Chance(0.5) ? 0 : random.Pick(std::vector<std::uint64_t>{1, 20, 40, 1ULL << 63}));
      std::string what = fmt::format("GetJobFields {} step {}", id.substr(0, 40), request->step());
      return Wrap("GetJobFields", std::move(request), std::move(what));
    }
  }
}

FuzzRequest SweepCall(FuzzRandom& random, const FuzzContext& context) {
  const std::string id = SweepId(random, context);
  switch (random.Below(4)) {
    case 0:
      return IdCall<v1::GetSweepRequest>("GetSweep", id);
    case 1:
      return IdCall<v1::CancelSweepRequest>("CancelSweep", id);
    case 2:
      return IdCall<v1::ResumeSweepRequest>("ResumeSweep", id);
    default:
      return IdCall<v1::DeleteSweepRequest>("DeleteSweep", id);
  }
}

FuzzRequest ListCall(FuzzRandom& random) {
  switch (random.Below(3)) {
    case 0: {
      auto request = std::make_unique<v1::ListJobsRequest>();
      request->set_page_size(100);
      request->add_states(v1::JOB_STATE_SUCCEEDED);
      const std::string what = "ListJobs: " + Mutate(*request, "", random);
      return Wrap("ListJobs", std::move(request), what);
    }
    case 1: {
      auto request = std::make_unique<v1::ListCalibrationsRequest>();
      request->set_min_porosity(0.1);
      request->add_tags("fuzz");
      const std::string what = "ListCalibrations: " + Mutate(*request, "", random);
      return Wrap("ListCalibrations", std::move(request), what);
    }
    default: {
      auto request = std::make_unique<v1::LookupCalibrationRequest>();
      request->set_porosity_2d(0.2);
      request->set_mean_radius_m(1e-3);
      request->set_permeability_m2(1e-13);
      const std::string what = "LookupCalibration: " + Mutate(*request, "", random);
      return Wrap("LookupCalibration", std::move(request), what);
    }
  }
}

// The bytes of a valid request, damaged, sent to its own method or another.
FuzzRequest RawBytes(FuzzRandom& random, const FuzzContext& context) {
  FuzzRequest request =
      random.Chance(0.5) ? SubmitScene(random, context, false) : JobCall(random, context);
  std::string& bytes = request.bytes;
  std::string what;
  switch (random.Below(6)) {
    case 0: {
      const int flips = random.Int(1, 8);
      for (int i = 0; i < flips && !bytes.empty(); ++i) {
        bytes[random.Below(bytes.size())] ^= static_cast<char>(1u << random.Below(8));
      }
      what = fmt::format("{} bits flipped", flips);
      break;
    }
    case 1:
      bytes.resize(random.Below(bytes.size() + 1));
      what = fmt::format("cut to {} bytes", bytes.size());
      break;
    case 2: {
      const int n = random.Int(1, 64);
      for (int i = 0; i < n; ++i) bytes.push_back(static_cast<char>(random.Below(256)));
      what = fmt::format("{} random bytes appended", n);
      break;
    }
    case 3: {
      bytes.assign(static_cast<std::size_t>(random.Int(1, 256)), '\0');
      for (char& c : bytes) c = static_cast<char>(random.Below(256));
      what = fmt::format("{} random bytes", bytes.size());
      break;
    }
    case 4:
      // A length prefix that claims more than follows.
      bytes = std::string("\x0a\xff\xff\xff\xff\x0f", 6) + bytes;
      what = "an overlong length prefix";
      break;
    default: {
      const std::vector<std::string> methods = {"GetJob",    "SubmitSweep",  "ListJobs",
                                                "SubmitJob", "GetJobFields", "LookupCalibration"};
      request.method = random.Pick(methods);
      what = "sent to " + request.method;
      break;
    }
  }
  request.message.reset();
  request.streaming = false;
  if (request.method == "WatchJob") request.method = "GetJob";
  request.type = SeepMethod(request.method).input_type();
  // The id the damaged bytes carry, where they still decode (a flipped bit may change it).
  request.id.clear();
  std::unique_ptr<Message> decoded(
      google::protobuf::MessageFactory::generated_factory()->GetPrototype(request.type)->New());
  // Quietly: protobuf logs every string of damaged bytes that is not UTF-8.
  const google::protobuf::LogSilencer quiet;
  if (decoded->ParseFromString(bytes)) {
    for (const char* name : {"id", "job_id"}) {
      if (const auto* field = request.type->FindFieldByName(name); field != nullptr) {
        request.id = decoded->GetReflection()->GetString(*decoded, field);
      }
    }
  }
  request.what = fmt::format("raw {} ({})", request.what, what);
  return request;
}

}  // namespace

const google::protobuf::MethodDescriptor& SeepMethod(const std::string& name) {
  static const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName("seep.v1.SeepService");
  const auto* method = service != nullptr ? service->FindMethodByName(name) : nullptr;
  if (method == nullptr) throw std::logic_error("no method seep.v1.SeepService." + name);
  return *method;
}

namespace {

// The codec's own limit on a packing's disks (core's scene validation): above it, a refusal.
constexpr std::uint64_t kAdmittedDisks = 20'000'000;
// The service's limit on a sweep's jobs (seep_service_sweeps.cc): above it, a refusal.
constexpr std::uint64_t kAdmittedSweepJobs = 10'000;

std::uint64_t DisksOf(const v1::Packing& packing) {
  if (packing.has_lattice()) {
    return std::uint64_t{packing.lattice().columns()} * packing.lattice().rows();
  }
  if (packing.has_random()) return packing.random().particle_count();
  return static_cast<std::uint64_t>(packing.particles().radius_m_size());
}

// A swept value of a packing size field, clamped to what a uint32 field can take.
std::uint64_t LargestSwept(const v1::SweepAxis& axis) {
  double most = 0.0;
  for (const double v : axis.numbers()) {
    if (v > most) most = v;  // NaN is never larger
  }
  return most >= 4294967295.0 ? 4294967295u : static_cast<std::uint64_t>(most);
}

std::uint64_t SweepDisks(const v1::Sweep& sweep) {
  v1::Packing packing =
      sweep.has_calibration() ? sweep.calibration().scene().packing() : sweep.scene().packing();
  std::uint64_t largest = DisksOf(packing);
  std::vector<v1::SweepAxis> axes(sweep.axes().begin(), sweep.axes().end());
  if (sweep.has_replicates()) {
    v1::SweepAxis seeds;
    seeds.set_path(sweep.replicates().seed_path());
    for (const std::uint64_t s : sweep.replicates().seeds())
      seeds.add_numbers(static_cast<double>(s));
    seeds.add_numbers(static_cast<double>(sweep.replicates().count()) + 8.0);
    axes.push_back(seeds);
  }
  for (const v1::SweepAxis& axis : axes) {
    v1::Packing point = packing;
    const std::uint64_t v = LargestSwept(axis);
    if (axis.path() == "packing.lattice.columns") {
      point.mutable_lattice()->set_columns(static_cast<std::uint32_t>(v));
    } else if (axis.path() == "packing.lattice.rows") {
      point.mutable_lattice()->set_rows(static_cast<std::uint32_t>(v));
    } else if (axis.path() == "packing.random.particle_count") {
      point.mutable_random()->set_particle_count(static_cast<std::uint32_t>(v));
    } else {
      continue;
    }
    largest = std::max(largest, DisksOf(point));
  }
  return largest;
}

FuzzRequest Draw(FuzzRandom& random, const FuzzContext& context) {
  const std::uint64_t roll = random.Below(100);
  if (roll < 34) return SubmitScene(random, context, /*mutate=*/true);
  if (roll < 40) return SubmitScene(random, context, /*mutate=*/false);
  if (roll < 45) return SubmitCalibration(random, context);
  if (roll < 50) return SubmitFork(random, context);
  if (roll < 60) return SubmitSweep(random, context);
  if (roll < 80) return JobCall(random, context);
  if (roll < 85) return SweepCall(random, context);
  if (roll < 92) return ListCall(random);
  return RawBytes(random, context);
}

}  // namespace

std::uint64_t LargestPacking(const FuzzRequest& request) {
  if (request.message == nullptr) return 0;
  if (const auto* submit = dynamic_cast<const v1::SubmitJobRequest*>(request.message.get())) {
    return std::max(DisksOf(submit->scene().packing()),
                    DisksOf(submit->calibration().scene().packing()));
  }
  if (const auto* sweep = dynamic_cast<const v1::SubmitSweepRequest*>(request.message.get())) {
    return SweepDisks(sweep->sweep());
  }
  return 0;
}

std::uint64_t SweepJobCount(const FuzzRequest& request) {
  const auto* submit = dynamic_cast<const v1::SubmitSweepRequest*>(request.message.get());
  if (submit == nullptr) return 0;
  const v1::Sweep& sweep = submit->sweep();
  std::uint64_t points = sweep.axes_size() > 0 ? 1 : 0;
  for (const v1::SweepAxis& axis : sweep.axes()) {
    const auto values =
        static_cast<std::uint64_t>(axis.numbers_size() + axis.texts_size() + axis.flags_size());
    points = sweep.combine() == v1::SWEEP_COMBINE_ZIP ? std::max(points, values)
                                                      : std::min(points * values, kAdmittedDisks);
  }
  if (sweep.has_replicates()) {
    const std::uint64_t seeds = sweep.replicates().seeds_size() > 0
                                    ? static_cast<std::uint64_t>(sweep.replicates().seeds_size())
                                    : sweep.replicates().count();
    points = std::min(std::max<std::uint64_t>(points, 1) * seeds, kAdmittedDisks);
  }
  return points;
}

FuzzRequest GenerateRequest(FuzzRandom& random, const FuzzContext& context,
                            const GeneratorLimits& limits) {
  int redrawn = 0;
  for (;;) {
    FuzzRequest request = Draw(random, context);
    const std::uint64_t disks = LargestPacking(request);
    const std::uint64_t jobs = SweepJobCount(request);
    const bool large_disks =
        limits.max_disks > 0 && disks > limits.max_disks && disks <= kAdmittedDisks;
    const bool large_sweep =
        limits.max_sweep_jobs > 0 && jobs > limits.max_sweep_jobs && jobs <= kAdmittedSweepJobs;
    if (!large_disks && !large_sweep) {
      request.redrawn = redrawn;
      return request;
    }
    ++redrawn;
  }
}

}  // namespace seep::fuzz

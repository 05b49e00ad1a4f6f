#include "codec/fork_scene.h"

#include <fmt/format.h>
#include <google/protobuf/util/message_differencer.h>

#include <vector>

namespace seep::service {
namespace {

using google::protobuf::Message;
using google::protobuf::util::MessageDifferencer;

// Keeps the top-level field of the first difference the differencer reports (it compares fields
// in the order of their numbers, which is the order a scene file lists them in).
class FirstDifference final : public MessageDifferencer::Reporter {
 public:
  void ReportAdded(const Message&, const Message&,
                   const std::vector<MessageDifferencer::SpecificField>& path) override {
    Note(path);
  }
  void ReportDeleted(const Message&, const Message&,
                     const std::vector<MessageDifferencer::SpecificField>& path) override {
    Note(path);
  }
  void ReportModified(const Message&, const Message&,
                      const std::vector<MessageDifferencer::SpecificField>& path) override {
    Note(path);
  }
  const google::protobuf::FieldDescriptor* field() const { return field_; }

 private:
  void Note(const std::vector<MessageDifferencer::SpecificField>& path) {
    if (field_ == nullptr && !path.empty()) field_ = path.front().field;
  }
  const google::protobuf::FieldDescriptor* field_ = nullptr;
};

std::string StageLabel(const v1::Scene& scene, int index) {
  const std::string& name = scene.stages(index).name();
  return fmt::format("stage {} ('{}')", index + 1,
                     name.empty() ? fmt::format("stage{}", index + 1) : name);
}

}  // namespace

core::Status CheckForkScene(const v1::Scene& parent, const v1::Scene& fork, const ForkPoint& at) {
  const google::protobuf::Descriptor* scene = v1::Scene::descriptor();
  MessageDifferencer everything_but_stages;
  everything_but_stages.IgnoreField(scene->FindFieldByName("name"));
  everything_but_stages.IgnoreField(scene->FindFieldByName("stages"));
  everything_but_stages.IgnoreField(v1::Solver::descriptor()->FindFieldByName("progress_every"));
  FirstDifference first;
  everything_but_stages.ReportDifferencesTo(&first);
  if (!everything_but_stages.Compare(parent, fork)) {
    return core::InvalidArgument(fmt::format(
        "scene{}: differs from the parent job {}'s (a fork continues the parent's run from its "
        "checkpoint at step {}: only the stages after its current stage, the name and "
        "solver.progress_every may change)",
        first.field() != nullptr ? "." + first.field()->name() : "", at.parent_job_id, at.step));
  }

  // The stages that had begun at the checkpoint: all of them once the parent's run was over.
  const int parent_stages = parent.stages_size();
  const bool over = at.stage_index >= static_cast<std::uint32_t>(parent_stages);
  const int begun = over ? parent_stages : static_cast<int>(at.stage_index) + 1;
  if (fork.stages_size() < begun) {
    return core::InvalidArgument(fmt::format(
        "scene.stages: {} stage(s), but the parent job {}'s checkpoint (step {}) is {} {}: a fork "
        "keeps every stage up to that one and may change or add only those after it",
        fork.stages_size(), at.parent_job_id, at.step, over ? "past its" : "in its",
        StageLabel(parent, begun - 1)));
  }
  for (int i = 0; i < begun; ++i) {
    if (MessageDifferencer::Equals(parent.stages(i), fork.stages(i))) continue;
    const bool current = !over && i == begun - 1;
    return core::InvalidArgument(fmt::format(
        "scene.stages[{}]: differs from the parent job {}'s {}, which {} at the checkpoint (step "
        "{}); only the stages after it may change",
        i, at.parent_job_id, StageLabel(parent, i), current ? "had begun" : "had ended", at.step));
  }
  if (over && fork.stages_size() == parent_stages) {
    return core::InvalidArgument(fmt::format(
        "scene.stages: nothing left to run: the parent job {}'s checkpoint (step {}) is its final "
        "state, after all its {} stage(s); add at least one stage after them",
        at.parent_job_id, at.step, parent_stages));
  }
  return core::Status::Ok();
}

}  // namespace seep::service

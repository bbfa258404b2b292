#include "output/search_why.hpp"

#include <algorithm>

#include "mmvk/search/explain.hpp"

namespace mmvk::crowd {

namespace {

Recording::FrameWhy frame_why(const Database& db, const FrameExplanation& e) {
  Recording::FrameWhy out;
  out.frame = std::int32_t(e.frame);
  out.clip = e.clip;
  out.clip_time_s = float(e.frame_in_clip) / db.fps();
  for (const ChannelCost& channel : e.channels) out.weighted.push_back(channel.weighted);
  out.multiplier = e.multiplier;
  out.bias = e.bias;
  out.cost = e.cost;
  out.exclusion = std::uint8_t(e.exclusion);
  return out;
}

}  // namespace

SearchWhyRecorder::SearchWhyRecorder(const Database& database, std::span<const std::uint32_t> agents,
                                     std::size_t crowd_agents)
    : database_(database),
      slot_of_(crowd_agents, -1),
      pending_(agents.size() * database.dims()),
      pending_params_(agents.size()) {
  for (std::size_t slot = 0; slot < agents.size(); ++slot) slot_of_[agents[slot]] = std::int32_t(slot);
}

void SearchWhyRecorder::submitted(std::span<const std::uint32_t> characters, const QueryBatch& batch) {
  const std::size_t dims = database_.dims();
  for (std::size_t i = 0; i < characters.size() && i < batch.size; ++i) {
    const std::int32_t slot = slot_of_[characters[i]];
    if (slot < 0) continue;
    std::copy_n(batch.features.begin() + std::ptrdiff_t(i * dims), dims,
                pending_.begin() + std::ptrdiff_t(std::size_t(slot) * dims));
    pending_params_[std::size_t(slot)] = batch.params.empty() ? QueryParams{} : batch.params[i];
  }
}

void SearchWhyRecorder::applied(std::uint32_t b, std::size_t search, std::uint32_t chosen) {
  const std::int32_t slot = slot_of_[b];
  if (slot < 0) return;
  const std::size_t dims = database_.dims(), row = std::size_t(slot) * dims;
  kept_.push_back({b, search, chosen, pending_params_[std::size_t(slot)], queries_.size()});
  queries_.insert(queries_.end(), pending_.begin() + std::ptrdiff_t(row), pending_.begin() + std::ptrdiff_t(row + dims));
}

Status SearchWhyRecorder::finish(Recording& r, ThreadPool& pool) const {
  const FeatureSchema& schema = database_.schema();
  r.channel_names.clear();
  for (const FeatureChannel& channel : schema.channels) r.channel_names.push_back(channel.name);
  r.clip_names.clear();
  for (const Clip& clip : database_.clips()) r.clip_names.push_back(clip.name);
  r.exclusion_names.clear();
  for (std::size_t i = 0; i < kExclusionCount; ++i) r.exclusion_names.emplace_back(exclusion_name(Exclusion(i)));
  std::vector<Recording::SearchWhy> explained(kept_.size());
  std::vector<Status> failed(pool.thread_count());
  const std::size_t dims = database_.dims();
  pool.parallel_for(kept_.size(), [&](std::size_t begin, std::size_t end, unsigned thread) {
    for (std::size_t i = begin; i < end && failed[thread].ok(); ++i) {
      const Kept& k = kept_[i];
      // The chosen and the continuing frame, explained after the reference
      // winner explain_query puts first: they are the last two asked.
      std::vector<std::uint32_t> asked;
      if (k.chosen != kNoFrame) asked.push_back(k.chosen);
      if (k.params.continuing_frame != kNoFrame) asked.push_back(k.params.continuing_frame);
      const auto query = std::span<const float>(queries_).subspan(k.row, dims);
      Result<Explanation> e = explain_query(database_, query, k.params, asked, 1);
      if (!e) {
        failed[thread] = make_error("viewer: explaining search " + std::to_string(k.search) + " of character " +
                                    std::to_string(k.agent) + ": " + e.message());
        return;
      }
      Recording::SearchWhy& why = explained[i];
      why.search = k.search;
      why.weights.assign(k.params.channel_weights.begin(), k.params.channel_weights.begin() +
                                                               std::ptrdiff_t(schema.channels.size()));
      why.continuing_bias = k.params.continuing_bias;
      why.continuing_multiplier = k.params.continuing_multiplier;
      std::size_t next = e->frames.size() - asked.size();
      if (k.chosen != kNoFrame) why.chosen = frame_why(database_, e->frames[next++]);
      if (k.params.continuing_frame != kNoFrame) why.continuing = frame_why(database_, e->frames[next]);
    }
  });
  for (const Status& status : failed) MMVK_TRY(status);
  r.why.assign(r.agent_count, {});
  for (std::size_t i = 0; i < kept_.size(); ++i) r.why[kept_[i].agent].push_back(std::move(explained[i]));
  return {};
}

}  // namespace mmvk::crowd

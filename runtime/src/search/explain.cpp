#include "mmvk/search/explain.hpp"

#include <cstdio>

#include "mmvk/search/reference_search.hpp"

namespace mmvk {

namespace {

FrameExplanation explain_frame(const Database& db, std::uint32_t frame, std::span<const float> query,
                               const QueryParams& params) {
  FrameExplanation out;
  out.frame = frame;
  out.clip = db.frame_clip()[frame];
  out.frame_in_clip = frame - db.clips()[out.clip].first_frame;
  out.exclusion = exclusion_of(db, frame, params);
  const FeatureSchema& schema = db.schema();
  const std::span<const float> row = db.row(frame);
  // Same order and operations as frame_cost(), so `total` and `cost` match
  // what every exact backend computes, bit for bit.
  std::uint32_t d = 0;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    ChannelCost channel;
    channel.name = schema.channels[c].name;
    channel.weight = params.channel_weights[c];
    const std::uint32_t end = d + schema.channels[c].dims();
    for (; d < end; ++d) {
      const float diff = row[d] - query[d];
      channel.sum += diff * diff;
    }
    channel.weighted = channel.weight * channel.sum;
    out.total += channel.weighted;
    out.channels.push_back(std::move(channel));
  }
  out.multiplier = db.frame_multiplier()[frame];
  out.bias = db.frame_bias()[frame];
  out.continuing = frame == params.continuing_frame;
  if (out.continuing) {
    out.continuing_bias = params.continuing_bias;
    out.continuing_multiplier = params.continuing_multiplier;
  }
  out.cost = frame_cost(db, frame, query, params);
  return out;
}

}  // namespace

std::string_view exclusion_name(Exclusion exclusion) {
  switch (exclusion) {
    case Exclusion::None: return "candidate";
    case Exclusion::DoNotUse: return "do_not_use";
    case Exclusion::EdgeExcluded: return "edge-excluded";
    case Exclusion::BlockTransition: return "block_transition (not the continuing frame)";
    case Exclusion::MissingTag: return "missing a require_all tag";
    case Exclusion::ExcludedTag: return "has an exclude_any tag";
    case Exclusion::ExclusionWindow: return "inside the continuing frame's exclusion window";
  }
  return "?";
}

Exclusion exclusion_of(const Database& db, std::uint32_t frame, const QueryParams& params) {
  const std::uint32_t flags = db.frame_flags()[frame];
  if ((flags & kFrameDoNotUse) != 0) return Exclusion::DoNotUse;
  if ((flags & kFrameEdgeExcluded) != 0) return Exclusion::EdgeExcluded;
  if ((flags & kFrameBlockTransition) != 0 && frame != params.continuing_frame) return Exclusion::BlockTransition;
  const TagMask tags = db.frame_tags()[frame];
  if ((tags & params.require_all) != params.require_all) return Exclusion::MissingTag;
  if ((tags & params.exclude_any) != 0) return Exclusion::ExcludedTag;
  // The window is the only rule left; is_candidate() is its definition.
  if (!is_candidate(db, frame, params)) return Exclusion::ExclusionWindow;
  return Exclusion::None;
}

Result<Explanation> explain_query(const Database& db, std::span<const float> query, const QueryParams& params,
                                  std::span<const std::uint32_t> frames, std::uint32_t k) {
  Explanation out;
  out.results.assign(k, Match{});
  const QueryBatch batch{query, std::span<const QueryParams>(&params, 1), 1};
  MMVK_TRY(validate_search(db, batch, k, out.results));
  for (std::uint32_t frame : frames) {
    if (frame >= db.frame_count()) {
      return make_error("explain: frame " + std::to_string(frame) + " is out of range (" +
                        std::to_string(db.frame_count()) + " frames)");
    }
  }
  ReferenceSearch reference(db);
  MMVK_TRY(reference.search(batch, k, out.results));
  if (out.results[0].frame != kNoFrame) out.frames.push_back(explain_frame(db, out.results[0].frame, query, params));
  for (std::uint32_t frame : frames) out.frames.push_back(explain_frame(db, frame, query, params));
  for (std::uint32_t frame = 0; frame < db.frame_count(); ++frame) {
    const Exclusion exclusion = exclusion_of(db, frame, params);
    if (exclusion == Exclusion::None) {
      ++out.candidates;
    } else {
      ++out.excluded[static_cast<std::size_t>(exclusion)];
    }
  }
  return out;
}

std::string format_explanation(const Database& db, const Explanation& e) {
  std::string text;
  char line[512];
  auto append = [&](const char* format, auto... args) {
    std::snprintf(line, sizeof(line), format, args...);
    text += line;
  };
  append("candidates: %u of %u frames\n", e.candidates, db.frame_count());
  for (std::size_t r = 1; r < kExclusionCount; ++r) {
    if (e.excluded[r] == 0) continue;
    append("  excluded, %s: %u\n", std::string(exclusion_name(static_cast<Exclusion>(r))).c_str(), e.excluded[r]);
  }
  text += "results:";
  for (const Match& m : e.results) {
    if (m.frame == kNoFrame) {
      text += " none";
    } else {
      append(" %u:%.9g", m.frame, double(m.cost));
    }
  }
  text += "\n";
  for (std::size_t i = 0; i < e.frames.size(); ++i) {
    const FrameExplanation& f = e.frames[i];
    const bool winner = i == 0 && !e.results.empty() && e.results[0].frame == f.frame;
    append("%s %u (clip %u '%s', frame %u): %s\n", winner ? "winner frame" : "frame", f.frame, f.clip,
           db.clips()[f.clip].name.c_str(), f.frame_in_clip, std::string(exclusion_name(f.exclusion)).c_str());
    for (const ChannelCost& c : f.channels) {
      append("  %-28s weight %-9.6g sum %-13.9g weighted %.9g\n", c.name.c_str(), double(c.weight), double(c.sum),
             double(c.weighted));
    }
    if (f.continuing) {
      append("  (total %.9g x multiplier %.9g + bias %.9g) x continuing_multiplier %.9g + continuing_bias %.9g",
             double(f.total), double(f.multiplier), double(f.bias), double(f.continuing_multiplier),
             double(f.continuing_bias));
    } else {
      append("  total %.9g x multiplier %.9g + bias %.9g", double(f.total), double(f.multiplier), double(f.bias));
    }
    append(" = cost %.9g\n", double(f.cost));
  }
  return text;
}

}  // namespace mmvk

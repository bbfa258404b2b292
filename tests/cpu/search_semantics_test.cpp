// The shared search rules (validate_search, is_candidate, frame_cost), the
// QueryBuilder and the explain output, on small synthetic databases.
#include <bit>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mmvk/search/explain.hpp"
#include "mmvk/query/query_builder.hpp"
#include "mmvk/search/reference_search.hpp"
#include "support/search_test_data.hpp"

namespace mmvk::test {
namespace {

TEST(ValidateSearch, EmptyDatabaseIsAnError) {
  DatabaseParts parts;
  parts.schema = synthetic_schema({2, 3});
  parts.fps = 30.0f;
  parts.normalization.assign(5, DimNormalization{});
  Result<Database> db = Database::create(std::move(parts));
  if (!db.ok()) {
    // Rejected at creation already: the message must say so.
    EXPECT_FALSE(db.message().empty());
    return;
  }
  std::vector<Match> out(1);
  const Status status = validate_search(*db, QueryBatch{{}, {}, 0}, 1, {});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("empty"), std::string::npos) << status.message();
  ReferenceSearch reference(*db);
  EXPECT_FALSE(reference.search(QueryBatch{{}, {}, 0}, 1, {}).ok());
}

TEST(IsCandidate, ExclusionWindowWrapsOnlyInLoopingClips) {
  const Database db = synthetic_database({.frames = 600, .clips = 6, .seed = 3, .constraints = true});
  const Clip& looping = db.clips()[0];
  const Clip& straight = db.clips()[2];  // clip 1 is short
  ASSERT_TRUE(looping.loop);
  ASSERT_FALSE(straight.loop);
  QueryParams p;
  p.continuing_frame = looping.first_frame + 1;
  p.exclusion_window = 3;
  EXPECT_TRUE(is_candidate(db, p.continuing_frame, p));                              // itself
  EXPECT_FALSE(is_candidate(db, looping.first_frame + 4, p));                        // 3 ahead
  EXPECT_TRUE(is_candidate(db, looping.first_frame + 30, p));                        // far
  EXPECT_FALSE(is_candidate(db, looping.first_frame + looping.frame_count - 2, p));  // 3 back, wrapped
  EXPECT_TRUE(is_candidate(db, looping.first_frame + looping.frame_count - 3, p));   // 4 back, wrapped
  p.continuing_frame = straight.first_frame + 1;
  EXPECT_TRUE(is_candidate(db, straight.first_frame + straight.frame_count - 4, p));  // no wrap
  EXPECT_FALSE(is_candidate(db, straight.first_frame + 3, p));
  // Other clips are never in the window.
  EXPECT_TRUE(is_candidate(db, db.clips()[3].first_frame + 1, p));
}

TEST(FrameCost, FollowsTheDocumentedOrder) {
  const Database db = synthetic_database({.frames = 300, .clips = 3, .seed = 5, .constraints = true});
  const std::vector<float> query = synthetic_queries(db, 1, 6);
  QueryParams p;
  p.channel_weights[1] = 0.5f;
  p.continuing_frame = 150;
  p.continuing_bias = -0.25f;
  for (std::uint32_t frame : {0u, 150u, 299u}) {
    float total = 0.0f;
    std::uint32_t d = 0;
    for (std::size_t c = 0; c < db.schema().channels.size(); ++c) {
      float sum = 0.0f;
      for (std::uint32_t end = d + db.schema().channels[c].dims(); d < end; ++d) {
        const float diff = db.row(frame)[d] - query[d];
        sum += diff * diff;
      }
      total += p.channel_weights[c] * sum;
    }
    float expected = db.frame_multiplier()[frame] * total + db.frame_bias()[frame];
    if (frame == 150) expected += p.continuing_bias;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(frame_cost(db, frame, query, p)), std::bit_cast<std::uint32_t>(expected));
  }
}

TEST(QueryBuilder, SetsChannelsByNameAndNormalizes) {
  DatabaseParts parts = synthetic_parts({.frames = 200, .clips = 2, .seed = 9, .channel_dims = {2, 3}});
  for (std::size_t d = 0; d < parts.normalization.size(); ++d) {
    parts.normalization[d] = DimNormalization{float(d), 2.0f + float(d)};
  }
  const Database db = make_database(std::move(parts));
  QueryBuilder builder(db);
  EXPECT_FALSE(builder.check_complete().ok());
  const std::vector<float> first = {1.0f, 2.0f};
  const std::vector<float> second = {3.0f, 4.0f, 5.0f};
  ASSERT_TRUE(builder.set("channel0", first).ok());
  ASSERT_TRUE(builder.set("channel1", second).ok());
  EXPECT_TRUE(builder.check_complete().ok());
  const std::vector<float> raw(builder.raw().begin(), builder.raw().end());
  EXPECT_EQ(raw, (std::vector<float>{1, 2, 3, 4, 5}));
  Result<std::vector<float>> normalized = builder.normalized();
  ASSERT_TRUE(normalized.ok());
  std::vector<float> expected(5);
  db.normalize(raw, expected);
  EXPECT_EQ(*normalized, expected);
  EXPECT_EQ((*normalized)[4], (5.0f - 4.0f) / 6.0f);

  // Errors name the channel and what it expects.
  const Status wrong_size = builder.set("channel1", first);
  ASSERT_FALSE(wrong_size.ok());
  EXPECT_NE(wrong_size.message().find("'channel1' expects 3 values, got 2"), std::string::npos) << wrong_size.message();
  const Status unknown = builder.set("trajectory", first);
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("unknown channel 'trajectory'"), std::string::npos) << unknown.message();
  EXPECT_NE(unknown.message().find("channel0, channel1"), std::string::npos) << unknown.message();
  const std::vector<float> nan = {1.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f};
  const Status not_finite = builder.set("channel1", nan);
  ASSERT_FALSE(not_finite.ok());
  EXPECT_NE(not_finite.message().find("not finite"), std::string::npos) << not_finite.message();

  // Schema-only builders normalize only against a matching database.
  QueryBuilder schema_only(db.schema());
  EXPECT_FALSE(schema_only.normalized().ok());
  std::vector<float> out(5);
  EXPECT_TRUE(schema_only.normalize(db, out).ok());
  QueryBuilder other(synthetic_schema({5}));
  EXPECT_FALSE(other.normalize(db, out).ok());

  QueryParams params;
  EXPECT_TRUE(set_channel_weight(db.schema(), params, "channel1", 0.0f).ok());
  EXPECT_EQ(params.channel_weights[1], 0.0f);
  EXPECT_FALSE(set_channel_weight(db.schema(), params, "nope", 1.0f).ok());
  EXPECT_FALSE(set_channel_weight(db.schema(), params, "channel0", -1.0f).ok());
}

// continuing_multiplier scales the continuing frame's whole cost (bias_i
// included) before continuing_bias is added; both steps rounded in float.
TEST(FrameCost, ContinuingMultiplierComesBeforeTheContinuingBias) {
  const Database db = synthetic_database({.frames = 300, .clips = 3, .seed = 5, .constraints = true});
  const std::vector<float> query = synthetic_queries(db, 1, 6);
  QueryParams p;
  p.continuing_frame = 150;
  p.continuing_bias = -0.25f;
  QueryParams plain = p;
  plain.continuing_frame = kNoFrame;
  for (const float multiplier : {0.0f, 0.3f, 1.0f, 1.7f}) {
    p.continuing_multiplier = multiplier;
    float expected = frame_cost(db, 150, query, plain);
    expected = expected * multiplier;
    expected = expected + p.continuing_bias;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(frame_cost(db, 150, query, p)), std::bit_cast<std::uint32_t>(expected))
        << multiplier;
    // Only the continuing frame.
    EXPECT_EQ(std::bit_cast<std::uint32_t>(frame_cost(db, 149, query, p)),
              std::bit_cast<std::uint32_t>(frame_cost(db, 149, query, plain)));
  }
  // The explanation shows it, with the same cost.
  p.continuing_multiplier = 0.5f;
  const std::vector<std::uint32_t> named = {150};
  Result<Explanation> e = explain_query(db, query, p, named, 1);
  ASSERT_TRUE(e.ok()) << e.message();
  const FrameExplanation& f = e->frames.back();
  EXPECT_TRUE(f.continuing);
  EXPECT_EQ(f.continuing_multiplier, 0.5f);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(f.cost), std::bit_cast<std::uint32_t>(frame_cost(db, 150, query, p)));
  const std::string text = format_explanation(db, *e);
  EXPECT_NE(text.find("x continuing_multiplier 0.5 + continuing_bias -0.25"), std::string::npos) << text;
}

TEST(Explain, BreaksDownTheWinnerAndNamesReasons) {
  const Database db = synthetic_database({.frames = 3000, .seed = 17, .constraints = true});
  const Clip& clip = db.clips()[3];  // loops; tags run and idle
  const std::uint32_t target = clip.first_frame + 40;
  const std::vector<float> query(db.row(target).begin(), db.row(target).end());
  QueryParams params;
  params.continuing_frame = clip.first_frame + 38;
  params.continuing_bias = -0.125f;
  params.exclusion_window = 5;
  params.exclude_any = kTagWalk;
  const std::vector<std::uint32_t> named = {
      clip.first_frame + 6,               // do-not-use
      db.clips()[4].first_frame + db.clips()[4].frame_count - 1,  // edge-excluded
      clip.first_frame + 22,              // block transition
      db.clips()[2].first_frame + 50,     // walk: excluded tag
      target,                             // inside the window
      params.continuing_frame,            // the continuing frame
  };
  Result<Explanation> e = explain_query(db, query, params, named, 3);
  ASSERT_TRUE(e.ok()) << e.message();
  ASSERT_EQ(e->frames.size(), named.size() + 1);
  const std::vector<Exclusion> reasons = {Exclusion::DoNotUse,    Exclusion::EdgeExcluded,    Exclusion::BlockTransition,
                                          Exclusion::ExcludedTag, Exclusion::ExclusionWindow, Exclusion::None};
  for (std::size_t i = 0; i < named.size(); ++i) {
    const FrameExplanation& f = e->frames[i + 1];
    EXPECT_EQ(f.frame, named[i]);
    EXPECT_EQ(f.exclusion, reasons[i]) << "frame " << f.frame << ": " << exclusion_name(f.exclusion);
    EXPECT_EQ(f.exclusion == Exclusion::None, is_candidate(db, f.frame, params));
  }
  // The winner's breakdown adds up to its cost, bit for bit.
  const FrameExplanation& winner = e->frames[0];
  EXPECT_EQ(winner.frame, e->results[0].frame);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(winner.cost), std::bit_cast<std::uint32_t>(e->results[0].cost));
  float total = 0.0f;
  for (const ChannelCost& c : winner.channels) total += c.weighted;
  EXPECT_EQ(std::bit_cast<std::uint32_t>(total), std::bit_cast<std::uint32_t>(winner.total));
  EXPECT_TRUE(e->frames.back().continuing);
  // Every frame is counted once.
  std::uint32_t counted = e->candidates;
  for (std::uint32_t n : e->excluded) counted += n;
  EXPECT_EQ(counted, db.frame_count());
  const std::string text = format_explanation(db, *e);
  EXPECT_NE(text.find("winner frame"), std::string::npos) << text;
  EXPECT_NE(text.find("exclusion window"), std::string::npos) << text;
  EXPECT_NE(text.find("continuing_bias"), std::string::npos) << text;
  // Bad input.
  const std::vector<std::uint32_t> out_of_range = {db.frame_count()};
  EXPECT_FALSE(explain_query(db, query, params, out_of_range).ok());
  EXPECT_FALSE(explain_query(db, std::span<const float>(query).first(3), params, {}).ok());
}

}  // namespace
}  // namespace mmvk::test

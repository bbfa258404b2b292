// The CPU reference: plain scalar brute force in the documented order. It is
// the oracle every other backend is tested against; it is meant to be
// obviously right, not fast.
#pragma once

#include <memory>

#include "mmvk/search/search.hpp"

namespace mmvk {

class ReferenceSearch final : public SearchBackend {
 public:
  // `database` must outlive the backend. Never fails; create() is the form
  // the backend registry uses, like every other backend's.
  explicit ReferenceSearch(const Database& database) : database_(&database) {}
  static Result<std::unique_ptr<ReferenceSearch>> create(const Database& database) {
    return std::make_unique<ReferenceSearch>(database);
  }

  std::string_view name() const override { return "reference"; }
  std::string device() const override { return cpu_device_text(1); }
  const Database& database() const override { return *database_; }
  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override;
  SearchStats stats() const override { return stats_; }
  void reset_stats() override { stats_ = {}; }

 private:
  const Database* database_;
  SearchStats stats_;
};

}  // namespace mmvk

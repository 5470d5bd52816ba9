#pragma once
/// @file scratch_ekf.h
/// @brief SCRATCH (reverted in the next commit): a strategy added only to follow the recipe
/// "A new fusion strategy" in docs/contributing.md once. It is the centralized EKF under another
/// name, so its estimates must equal centralized's byte for byte.

#include "estimator/filter/centralized_ekf.h"

namespace meshnav::estimator {

class ScratchEkf final : public CentralizedEkf {
 public:
  using CentralizedEkf::CentralizedEkf;
  std::string name() const override { return "scratch"; }
  std::unique_ptr<FusionStrategy> clone() const override { return std::make_unique<ScratchEkf>(*this); }
};

}  // namespace meshnav::estimator

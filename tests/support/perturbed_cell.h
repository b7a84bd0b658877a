// SPDX-License-Identifier: AGPL-3.0-or-later
// A finite element's corners moved at random, for quality metric tests.
#pragma once

#include <random>

namespace labelmesh::testing {

// `cell` (an array of points) with every coordinate moved by up to
// `amplitude` either way.
template <typename Cell>
Cell perturbed(Cell cell, std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  for (auto& point : cell) {
    for (double& x : point) x += noise(rng);
  }
  return cell;
}

}  // namespace labelmesh::testing

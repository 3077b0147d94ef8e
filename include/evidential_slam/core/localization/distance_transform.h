// The exact Euclidean distance transform of a binary grid (Felzenszwalb and Huttenlocher,
// "Distance transforms of sampled functions", Theory of Computing 2012): a 1-D lower envelope of
// parabolas along the rows, then along the columns, O(cells).
#pragma once

#include <cstdint>
#include <vector>

namespace evidential_slam {

// Squared distance, in cells, from each cell of a width x height grid (row-major) to the
// nearest cell whose `seeds` entry is non-zero; +infinity everywhere when there is no seed.
// Throws std::invalid_argument when seeds.size() != width * height or a size is negative.
std::vector<float> squaredDistanceTransform(const std::vector<uint8_t>& seeds, int width,
                                            int height);

// The distance in whole cells (the floor of the Euclidean distance) from each cell to the nearest
// seed (a non-zero entry), saturated at 255, written over `grid` in place (255 everywhere when
// there is no seed): floor(sqrt(squaredDistanceTransform)) capped at 255, in a quarter of its
// memory (a float per cell, in `scratch`, reused across calls). Throws std::invalid_argument as
// squaredDistanceTransform.
void saturatedDistanceTransform(std::vector<uint8_t>* grid, int width, int height,
                                std::vector<float>* scratch);

}  // namespace evidential_slam

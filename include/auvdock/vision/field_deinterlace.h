// Interlaced video (two fields, even and odd rows, exposed ~1/50-1/60 s apart) shows "combing"
// on anything that moves: a light becomes two half-height blobs offset sideways, and its
// centroid lands between them. Keeping one field and rebuilding the other rows from it removes
// the combing at the cost of half the vertical resolution.
//
// LineDoubleEvenField: rows 0, 2, 4, ... are kept as they are; odd row 2i + 1 is the mean of rows
// 2i and 2i + 2 (the last odd row copies the row above). Linear interpolation, not duplication,
// so that pixel coordinates keep their meaning (duplication would shift v by +0.5 px).
#pragma once

#include <opencv2/core.hpp>

namespace auvdock {

// Any depth and channel count; an image of fewer than 2 rows is returned as a copy.
cv::Mat LineDoubleEvenField(const cv::Mat& image);

}  // namespace auvdock

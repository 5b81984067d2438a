/// @file figures.hpp
/// The strip of annotated frames (one per family, or a few of one sequence): a small PNG, so that
/// docs/images can hold it. The plots are drawn from the programs' CSV by scripts/figures.py. No paper
/// equation.
#pragma once

#include "report.hpp"
#include "runner.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace dyncull {
namespace vo {

/// One frame of the strip: an annotated frame (draw_features) and the label written over its caption bar.
struct StripFrame {
  std::string path, label;
};

/// Tiles the annotated frames (those that exist), each scaled to `tile_width` with its label on top, into
/// rows of `per_row`, each channel reduced to `levels` grey levels (256: unchanged); false when none could be read.
inline bool write_frame_strip(const std::string& path, const std::vector<StripFrame>& frames, int tile_width = 240,
                              int per_row = 4, int levels = 4) {
  std::vector<cv::Mat> tiles;
  for (const StripFrame& f : frames) {
    cv::Mat img = cv::imread(f.path, cv::IMREAD_COLOR);
    if (img.empty()) continue;
    cv::Mat small;
    cv::resize(img, small, cv::Size(tile_width, img.rows * tile_width / img.cols), 0, 0, cv::INTER_AREA);
    cv::rectangle(small, {0, 0}, {small.cols, 15}, cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(small, f.label, {4, 11}, cv::FONT_HERSHEY_SIMPLEX, 0.36, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    tiles.push_back(small);
  }
  if (tiles.empty()) return false;
  const int cols = std::min(per_row, static_cast<int>(tiles.size()));
  const int rows = (static_cast<int>(tiles.size()) + cols - 1) / cols;
  const int tile_h = tiles[0].rows;
  cv::Mat strip(rows * tile_h, cols * tile_width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const int r = static_cast<int>(i) / cols, c = static_cast<int>(i) % cols;
    cv::Mat roi = strip(cv::Rect(c * tile_width, r * tile_h, tile_width, std::min(tile_h, tiles[i].rows)));
    tiles[i](cv::Rect(0, 0, tile_width, roi.rows)).copyTo(roi);
  }
  // Four levels a channel for the sim: its fine texture would otherwise make the PNG ten times larger.
  const int step = 256 / std::clamp(levels, 2, 256), top = (255 / step) * step;
  if (step > 1)
    strip.forEach<cv::Vec3b>([&](cv::Vec3b& px, const int*) {
      for (int c = 0; c < 3; ++c) px[c] = static_cast<std::uint8_t>((px[c] / step) * step * 255 / top);
    });
  return cv::imwrite(path, strip, {cv::IMWRITE_PNG_COMPRESSION, 9});
}

}  // namespace vo
}  // namespace dyncull

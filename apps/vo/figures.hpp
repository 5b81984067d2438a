/// @file figures.hpp
/// The demo's two summary pictures: the median ATE per scene family and strategy (a grouped bar chart on a
/// log axis, since no culling is often ten times worse than the rest), and a strip of one annotated frame
/// per family. Small PNGs, so that docs/images can hold them. No paper equation.
#pragma once

#include "dyncull/core/pixel.hpp"
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

/// Grouped bars: per family (left to right) the median ATE of each strategy, on a log10 axis in cm.
inline bool plot_family_summary(const std::string& path, const std::vector<FamilyStrategySummary>& rows) {
  std::vector<std::string> families, strategies;
  double lo = 1e300, hi = 0;
  for (const FamilyStrategySummary& r : rows) {
    if (r.motion != "all" || !(r.median_ate_m > 0)) continue;
    if (std::find(families.begin(), families.end(), r.family) == families.end()) families.push_back(r.family);
    if (std::find(strategies.begin(), strategies.end(), r.strategy) == strategies.end()) strategies.push_back(r.strategy);
    lo = std::min(lo, 100 * r.median_ate_m);
    hi = std::max(hi, 100 * r.median_ate_m);
  }
  if (families.empty()) return false;
  const double log_lo = std::floor(std::log10(lo)), log_hi = std::ceil(std::log10(hi));
  const int left = 56, top = 30, plot_h = 260, bar_w = 7, group_gap = 14;
  const int group_w = std::max(bar_w * static_cast<int>(strategies.size()) + group_gap, 84);  // room for the name
  const int width = left + group_w * static_cast<int>(families.size()) + 10;
  const int legend_rows = (static_cast<int>(strategies.size()) + 3) / 4;
  cv::Mat img(top + plot_h + 40 + 18 * legend_rows, std::max(width, 560), CV_8UC3, cv::Scalar(255, 255, 255));
  auto y_of = [&](double cm) {
    const double t = (std::log10(cm) - log_lo) / std::max(log_hi - log_lo, 1.0);
    return top + plot_h - clamped_int(std::round(t * plot_h), -plot_h, 2 * plot_h);  // NaN (cm <= 0): the top
  };
  const cv::Scalar ink(0, 0, 0), grid(215, 215, 215);
  for (double e = log_lo; e <= log_hi; ++e) {
    const double cm = std::pow(10.0, e);
    cv::line(img, {left, y_of(cm)}, {width - 10, y_of(cm)}, grid, 1);
    char label[32];
    std::snprintf(label, sizeof label, "%g cm", cm);
    cv::putText(img, label, {4, y_of(cm) + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.38, ink, 1, cv::LINE_AA);
  }
  for (std::size_t f = 0; f < families.size(); ++f) {
    const int x0 = left + static_cast<int>(f) * group_w;
    for (std::size_t s = 0; s < strategies.size(); ++s) {
      for (const FamilyStrategySummary& r : rows) {
        if (r.motion != "all" || r.family != families[f] || r.strategy != strategies[s] || !(r.median_ate_m > 0)) continue;
        const int x = x0 + static_cast<int>(s) * bar_w;
        cv::rectangle(img, {x, y_of(100 * r.median_ate_m)}, {x + bar_w - 2, top + plot_h}, strategy_colour(s), cv::FILLED);
      }
    }
    cv::putText(img, families[f], {x0, top + plot_h + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.36, ink, 1, cv::LINE_AA);
  }
  cv::putText(img, "median ATE RMSE per scene family (log scale)", {left, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45, ink, 1,
              cv::LINE_AA);
  for (std::size_t s = 0; s < strategies.size(); ++s) {
    const int x = left + static_cast<int>(s % 4) * 130, y = top + plot_h + 34 + 18 * static_cast<int>(s / 4);
    cv::rectangle(img, {x, y - 9}, {x + 12, y + 1}, strategy_colour(s), cv::FILLED);
    cv::putText(img, strategies[s], {x + 18, y}, cv::FONT_HERSHEY_SIMPLEX, 0.38, ink, 1, cv::LINE_AA);
  }
  return cv::imwrite(path, img);
}

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

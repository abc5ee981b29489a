// A small SVG chart writer for the reproduced figures: axes with ticks and labels (linear or log10),
// polylines, points, error bars, bars and a legend. Output is deterministic text (fixed number
// formatting, no timestamps), so regenerated figures diff cleanly.
#pragma once

#include <string>
#include <vector>

namespace qem::reproduce {

struct Series {
  std::string label;
  std::vector<double> x, y;
  std::vector<double> err;  ///< optional: +- error bar per point (same length as y)
  enum class Style { Line, Points, LinePoints, Bars } style = Style::LinePoints;
};

struct Plot {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
  /// Category labels for bar charts (x = 0, 1, ... index them); empty for numeric x.
  std::vector<std::string> categories;
  std::vector<Series> series;
  /// Optional reference line y = x (HG99 Fig. 8: actual equals optimal).
  bool diagonal = false;
};

/// Renders the plot as a standalone SVG document (width x height pixels).
std::string render_svg(const Plot& plot, int width = 640, int height = 420);

}  // namespace qem::reproduce

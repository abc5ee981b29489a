#include "reproduce/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace qem::reproduce {

namespace {

const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string tick_label(double v) {
  char buf[32];
  if (v != 0 && (std::abs(v) < 1e-3 || std::abs(v) >= 1e5))
    std::snprintf(buf, sizeof buf, "%.0e", v);
  else
    std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

/// An axis: data range, mapping to pixels, and "nice" tick positions (1-2-5 steps, or decades).
struct Axis {
  double lo = 0, hi = 1;
  bool log = false;
  double p0 = 0, p1 = 1;  // pixel positions of lo and hi

  double t(double v) const { return log ? std::log10(v) : v; }
  double map(double v) const {
    double a = t(lo), b = t(hi);
    return p0 + (t(v) - a) / (b - a) * (p1 - p0);
  }
  std::vector<double> ticks() const {
    std::vector<double> out;
    if (log) {
      for (double e = std::floor(std::log10(lo)); e <= std::ceil(std::log10(hi)); e += 1) {
        double v = std::pow(10.0, e);
        if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) out.push_back(v);
      }
      return out;
    }
    double span = hi - lo, raw = span / 6, mag = std::pow(10.0, std::floor(std::log10(raw)));
    double step = mag * (raw / mag < 1.5 ? 1 : raw / mag < 3.5 ? 2 : raw / mag < 7.5 ? 5 : 10);
    for (double v = std::ceil(lo / step) * step; v <= hi + step * 1e-9; v += step)
      out.push_back(std::abs(v) < step * 1e-9 ? 0 : v);
    return out;
  }
};

void fit(Axis& axis, const std::vector<double>& values, bool include_zero) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (std::isfinite(v) && (!axis.log || v > 0)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!std::isfinite(lo)) lo = axis.log ? 1 : 0, hi = axis.log ? 10 : 1;
  if (axis.log) {
    lo = std::pow(10.0, std::floor(std::log10(lo)));
    hi = std::pow(10.0, std::ceil(std::log10(hi)));
    if (hi <= lo) hi = lo * 10;
  } else {
    if (include_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    if (hi <= lo) hi = lo + 1;
    double pad = 0.05 * (hi - lo);
    if (!(include_zero && lo == 0)) lo -= pad;
    hi += pad;
  }
  axis.lo = lo, axis.hi = hi;
}

}  // namespace

std::string render_svg(const Plot& plot, int width, int height) {
  const double left = 80, right = 20, top = 40, bottom = 60;
  const bool bars = !plot.categories.empty();
  Axis ax, ay;
  ax.log = plot.log_x && !bars, ay.log = plot.log_y;
  std::vector<double> xs, ys;
  for (const Series& s : plot.series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    for (std::size_t i = 0; i < s.y.size(); ++i) {
      double e = i < s.err.size() ? s.err[i] : 0;
      ys.push_back(s.y[i] + e);
      ys.push_back(ay.log && s.y[i] - e <= 0 ? s.y[i] : s.y[i] - e);
    }
  }
  if (bars) {
    ax.lo = -0.5, ax.hi = double(plot.categories.size()) - 0.5;
  } else {
    fit(ax, xs, false);
  }
  bool any_bars = false;
  for (const Series& s : plot.series) any_bars |= s.style == Series::Style::Bars;
  fit(ay, ys, any_bars && !ay.log);
  if (plot.diagonal && !ax.log && !ay.log) {
    double lo = std::min(ax.lo, ay.lo), hi = std::max(ax.hi, ay.hi);
    ax.lo = ay.lo = lo, ax.hi = ay.hi = hi;
  }
  ax.p0 = left, ax.p1 = width - right;
  ay.p0 = height - bottom, ay.p1 = top;

  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) +
                  "\" height=\"" + std::to_string(height) + "\" viewBox=\"0 0 " + std::to_string(width) +
                  " " + std::to_string(height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + fmt(width / 2.0) + "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" +
       escape(plot.title) + "</text>\n";
  // Frame, grid and ticks.
  s += "<rect x=\"" + fmt(left) + "\" y=\"" + fmt(top) + "\" width=\"" + fmt(width - left - right) +
       "\" height=\"" + fmt(height - top - bottom) + "\" fill=\"none\" stroke=\"black\"/>\n";
  if (bars) {
    for (std::size_t i = 0; i < plot.categories.size(); ++i)
      s += "<text x=\"" + fmt(ax.map(double(i))) + "\" y=\"" + fmt(height - bottom + 18) +
           "\" text-anchor=\"middle\">" + escape(plot.categories[i]) + "</text>\n";
  } else {
    for (double v : ax.ticks()) {
      double px = ax.map(v);
      s += "<line x1=\"" + fmt(px) + "\" y1=\"" + fmt(top) + "\" x2=\"" + fmt(px) + "\" y2=\"" +
           fmt(height - bottom) + "\" stroke=\"#ddd\"/>\n";
      s += "<text x=\"" + fmt(px) + "\" y=\"" + fmt(height - bottom + 18) + "\" text-anchor=\"middle\">" +
           tick_label(v) + "</text>\n";
    }
  }
  for (double v : ay.ticks()) {
    double py = ay.map(v);
    s += "<line x1=\"" + fmt(left) + "\" y1=\"" + fmt(py) + "\" x2=\"" + fmt(width - right) + "\" y2=\"" +
         fmt(py) + "\" stroke=\"#ddd\"/>\n";
    s += "<text x=\"" + fmt(left - 6) + "\" y=\"" + fmt(py + 4) + "\" text-anchor=\"end\">" + tick_label(v) +
         "</text>\n";
  }
  s += "<text x=\"" + fmt((left + width - right) / 2) + "\" y=\"" + fmt(height - 18.0) +
       "\" text-anchor=\"middle\">" + escape(plot.x_label) + "</text>\n";
  s += "<text transform=\"translate(18," + fmt((top + height - bottom) / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">" + escape(plot.y_label) + "</text>\n";
  if (plot.diagonal) {
    double a = std::max(ax.lo, ay.lo), b = std::min(ax.hi, ay.hi);
    s += "<line x1=\"" + fmt(ax.map(a)) + "\" y1=\"" + fmt(ay.map(a)) + "\" x2=\"" + fmt(ax.map(b)) +
         "\" y2=\"" + fmt(ay.map(b)) + "\" stroke=\"#888\" stroke-dasharray=\"4 3\"/>\n";
  }

  // Data. Bars of several series sit side by side within a category.
  int bar_series = 0, bar_index = 0;
  for (const Series& se : plot.series) bar_series += se.style == Series::Style::Bars;
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    const Series& se = plot.series[k];
    const char* color = kColors[k % 6];
    auto ok = [&](std::size_t i) {
      return std::isfinite(se.x[i]) && std::isfinite(se.y[i]) && (!ax.log || se.x[i] > 0) &&
             (!ay.log || se.y[i] > 0);
    };
    if (se.style == Series::Style::Bars) {
      double slot = 0.8 / std::max(1, bar_series), w = slot * (ax.map(1) - ax.map(0));
      for (std::size_t i = 0; i < se.x.size() && i < se.y.size(); ++i) {
        if (!ok(i)) continue;
        double cx = ax.map(se.x[i] - 0.4 + slot * (bar_index + 0.5));
        double base = ay.log ? ay.map(ay.lo) : ay.map(0), py = ay.map(se.y[i]);
        s += "<rect x=\"" + fmt(cx - w / 2) + "\" y=\"" + fmt(std::min(py, base)) + "\" width=\"" + fmt(w) +
             "\" height=\"" + fmt(std::abs(base - py)) + "\" fill=\"" + color + "\"/>\n";
      }
      ++bar_index;
    } else {
      if (se.style != Series::Style::Points) {
        std::string pts;
        for (std::size_t i = 0; i < se.x.size() && i < se.y.size(); ++i)
          if (ok(i)) pts += fmt(ax.map(se.x[i])) + "," + fmt(ay.map(se.y[i])) + " ";
        s += "<polyline fill=\"none\" stroke=\"" + std::string(color) + "\" stroke-width=\"1.5\" points=\"" +
             pts + "\"/>\n";
      }
      if (se.style != Series::Style::Line)
        for (std::size_t i = 0; i < se.x.size() && i < se.y.size(); ++i)
          if (ok(i))
            s += "<circle cx=\"" + fmt(ax.map(se.x[i])) + "\" cy=\"" + fmt(ay.map(se.y[i])) +
                 "\" r=\"3\" fill=\"" + color + "\"/>\n";
    }
    for (std::size_t i = 0; i < se.err.size() && i < se.y.size(); ++i) {
      if (!ok(i) || !(se.err[i] > 0)) continue;
      double lo = se.y[i] - se.err[i], hi = se.y[i] + se.err[i];
      if (ay.log && lo <= 0) lo = ay.lo;
      double px = ax.map(se.x[i]);
      s += "<line x1=\"" + fmt(px) + "\" y1=\"" + fmt(ay.map(lo)) + "\" x2=\"" + fmt(px) + "\" y2=\"" +
           fmt(ay.map(hi)) + "\" stroke=\"" + color + "\"/>\n";
      for (double yy : {lo, hi})
        s += "<line x1=\"" + fmt(px - 4) + "\" y1=\"" + fmt(ay.map(yy)) + "\" x2=\"" + fmt(px + 4) +
             "\" y2=\"" + fmt(ay.map(yy)) + "\" stroke=\"" + color + "\"/>\n";
    }
  }
  // Legend, top right inside the frame.
  double ly = top + 16;
  std::size_t labelled = 0;
  for (const Series& se : plot.series) labelled += !se.label.empty();
  if (labelled)
    s += "<rect x=\"" + fmt(width - right - 176) + "\" y=\"" + fmt(top + 3) + "\" width=\"172\" height=\"" +
         fmt(16.0 * double(labelled) + 4) + "\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#ccc\"/>\n";
  for (std::size_t k = 0; k < plot.series.size(); ++k) {
    if (plot.series[k].label.empty()) continue;
    double lx = width - right - 170;
    s += "<rect x=\"" + fmt(lx) + "\" y=\"" + fmt(ly - 9) + "\" width=\"12\" height=\"10\" fill=\"" +
         kColors[k % 6] + "\"/>\n";
    s += "<text x=\"" + fmt(lx + 18) + "\" y=\"" + fmt(ly) + "\">" + escape(plot.series[k].label) +
         "</text>\n";
    ly += 16;
  }
  s += "</svg>\n";
  return s;
}

}  // namespace qem::reproduce

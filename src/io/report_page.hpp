// ctid — the HTML report's page writer (private to src/io): escaping, the plot data as JSON, and Page, which
// collects sections, tables, text and uPlot charts into one self-contained page.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ctid/core/check.hpp"
#include "ctid/data/iddata.hpp"

namespace ctid {
namespace report_assets {
extern const char* const kUplotJs;
extern const char* const kUplotCss;
extern const bool kHaveUplot;
}  // namespace report_assets

namespace report_detail {

inline std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

inline std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '<') {  // keeps "</script>" out of the embedded JSON
      o += "\\u003c";
      continue;
    }
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o + "\"";
}

inline std::string js_number(double v, int digits = 6) {
  if (!std::isfinite(v)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

inline std::string json_array(const Eigen::VectorXd& v, int digits = 6) {
  std::string o = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i) o += ',';
    o += js_number(v(i), digits);
  }
  return o + "]";
}

struct Series {
  std::string label;
  Eigen::VectorXd y;
  bool dashed = false;
  bool light = false;    // a band edge
  bool neutral = false;  // the measured signal among models (dark grey: the models keep their colours across plots)
  int digits = 6;        // significant digits written (17: the doubles themselves, for a reader that checks them)
};

struct Plot {
  std::string title, xlabel, ylabel;
  Eigen::VectorXd x;
  std::vector<Series> series;
  bool logx = false;
  bool bars = false;
};

// Points drawn as markers on equal footing with the origin and the axes through it (a pole-zero map).
struct PointSet {
  std::string label;
  Eigen::VectorXd x, y;
  char marker = 'x';   // 'x' cross, 'o' circle, '.' dot
  bool light = false;  // a cloud (drawn first, pale)
};
struct Scatter {
  std::string title, xlabel, ylabel;
  std::vector<PointSet> sets;
};

struct Heatmap {
  std::string title, xlabel, ylabel;
  Eigen::VectorXd x, y;
  Eigen::MatrixXd z;  // z(i, j) at (x(j), y(i))
};

class Page {
 public:
  void section(const std::string& title) { body_ << "<h2>" << escape(title) << "</h2>\n"; }
  void text(const std::string& html) { body_ << "<p>" << html << "</p>\n"; }
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
    body_ << "<table><tr>";
    for (const auto& h : header) body_ << "<th>" << escape(h) << "</th>";
    body_ << "</tr>\n";
    for (const auto& r : rows) {
      body_ << "<tr>";
      for (const auto& c : r) body_ << "<td>" << escape(c) << "</td>";
      body_ << "</tr>\n";
    }
    body_ << "</table>\n";
  }
  void plot(const Plot& p) {
    const std::string id = "plot" + std::to_string(n_++);
    body_ << "<div class=\"plot\" id=\"" << id << "\"></div>\n";
    std::ostringstream s;
    s << "{\"id\":\"" << id << "\",\"kind\":\"line\",\"title\":" << json_string(p.title)
      << ",\"xlabel\":" << json_string(p.xlabel) << ",\"ylabel\":" << json_string(p.ylabel)
      << ",\"logx\":" << (p.logx ? "true" : "false") << ",\"bars\":" << (p.bars ? "true" : "false")
      << ",\"x\":" << json_array(p.x) << ",\"series\":[";
    for (size_t i = 0; i < p.series.size(); ++i)
      s << (i ? "," : "") << "{\"label\":" << json_string(p.series[i].label) << ",\"dashed\":"
        << (p.series[i].dashed ? "true" : "false") << ",\"light\":" << (p.series[i].light ? "true" : "false")
        << ",\"neutral\":" << (p.series[i].neutral ? "true" : "false")
        << ",\"y\":" << json_array(p.series[i].y, p.series[i].digits) << "}";
    s << "]}";
    specs_.push_back(s.str());
  }
  void scatter(const Scatter& p) {
    const std::string id = "plot" + std::to_string(n_++);
    body_ << "<div class=\"plot\" id=\"" << id << "\"></div>\n";
    std::ostringstream s;
    s << "{\"id\":\"" << id << "\",\"kind\":\"scatter\",\"title\":" << json_string(p.title)
      << ",\"xlabel\":" << json_string(p.xlabel) << ",\"ylabel\":" << json_string(p.ylabel) << ",\"sets\":[";
    for (size_t i = 0; i < p.sets.size(); ++i)
      s << (i ? "," : "") << "{\"label\":" << json_string(p.sets[i].label) << ",\"marker\":\"" << p.sets[i].marker
        << "\",\"light\":" << (p.sets[i].light ? "true" : "false") << ",\"x\":" << json_array(p.sets[i].x)
        << ",\"y\":" << json_array(p.sets[i].y) << "}";
    s << "]}";
    specs_.push_back(s.str());
  }
  void heatmap(const Heatmap& h) {
    const std::string id = "plot" + std::to_string(n_++);
    body_ << "<div class=\"plot heat\" id=\"" << id << "\"></div>\n";
    std::ostringstream s;
    s << "{\"id\":\"" << id << "\",\"kind\":\"heatmap\",\"title\":" << json_string(h.title)
      << ",\"xlabel\":" << json_string(h.xlabel) << ",\"ylabel\":" << json_string(h.ylabel)
      << ",\"x\":" << json_array(h.x) << ",\"y\":" << json_array(h.y) << ",\"z\":[";
    for (Eigen::Index i = 0; i < h.z.rows(); ++i) s << (i ? "," : "") << json_array(h.z.row(i).transpose());
    s << "]}";
    specs_.push_back(s.str());
  }
  std::string render(const std::string& title) const {
    std::ostringstream o;
    o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << escape(title)
      << "</title>\n<style>" << report_assets::kUplotCss << "\n" << kCss << "</style>\n</head><body>\n<h1>"
      << escape(title) << "</h1>\n";
    if (!report_assets::kHaveUplot)
      o << "<p class=\"warn\">This ctid was built without the plotting library (run scripts/install-deps.sh and "
           "rebuild): the plots are missing.</p>\n";
    o << body_.str() << "<pre id=\"ctid-selfcheck\">pending</pre>\n<script id=\"ctid-plots\" type=\"application/json\">[";
    for (size_t i = 0; i < specs_.size(); ++i) o << (i ? ",\n" : "\n") << specs_[i];
    o << "]</script>\n<script>" << report_assets::kUplotJs << "</script>\n<script>" << kJs << "</script>\n</body></html>\n";
    return o.str();
  }

 private:
  static constexpr const char* kCss = R"css(
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1000px; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 1.8em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
td, th { border: 1px solid #ccc; padding: 2px 8px; text-align: left; font-variant-numeric: tabular-nums; }
.plot { margin: 0.8em 0; } .plot .title { font-weight: 600; font-size: 0.95em; }
.warn { color: #a40; } #ctid-selfcheck { display: none; } .legend { font-size: 0.85em; margin-top: 0.3em; }
code { background: #f4f4f4; padding: 1px 4px; }
)css";
  static constexpr const char* kJs = R"js(
(function () {
  let errors = 0;
  window.addEventListener('error', function () { errors++; });
  const colors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b'];
  const specs = JSON.parse(document.getElementById('ctid-plots').textContent);
  function title(el, p) {
    const t = document.createElement('div'); t.className = 'title'; t.textContent = p.title; el.appendChild(t);
  }
  function line(el, p) {
    title(el, p);
    if (typeof uPlot === 'undefined') return;
    const data = [p.x].concat(p.series.map(s => s.y));
    let c = 0;
    const series = [{ label: p.xlabel }].concat(p.series.map(function (s) {
      const col = s.light ? '#9ab' : s.neutral ? '#444' : colors[(c++) % colors.length];
      const o = { label: s.label, stroke: col, width: s.light ? 1 : 1.5, points: { show: false } };
      if (s.dashed || s.light) o.dash = [6, 4];
      if (p.bars && !s.dashed) { o.paths = uPlot.paths.bars({ size: [0.3, 6] }); o.fill = col; }
      return o;
    }));
    const opts = {
      width: Math.max(400, el.clientWidth || 900), height: 260, series: series,
      scales: { x: p.logx ? { time: false, distr: 3 } : { time: false } },
      axes: [{ label: p.xlabel }, { label: p.ylabel }],
      legend: { live: false }
    };
    new uPlot(opts, data, el);
  }
  function heatmap(el, p) {
    title(el, p);
    const W = 480, H = 400, m = 50;
    const cv = document.createElement('canvas'); cv.width = W + m + 70; cv.height = H + m; el.appendChild(cv);
    const g = cv.getContext('2d');
    let lo = Infinity, hi = -Infinity;
    p.z.forEach(r => r.forEach(v => { if (v !== null) { lo = Math.min(lo, v); hi = Math.max(hi, v); } }));
    const nx = p.x.length, ny = p.y.length, cw = W / nx, ch = H / ny;
    function col(v) {
      const f = hi > lo ? (v - lo) / (hi - lo) : 0.5;
      return 'hsl(' + Math.round(240 - 240 * f) + ',80%,' + Math.round(30 + 35 * f) + '%)';
    }
    for (let i = 0; i < ny; i++) for (let j = 0; j < nx; j++) {
      const v = p.z[i][j]; if (v === null) continue;
      g.fillStyle = col(v); g.fillRect(m + j * cw, H - (i + 1) * ch, Math.ceil(cw), Math.ceil(ch));
    }
    g.fillStyle = '#222'; g.font = '12px sans-serif';
    g.fillText(p.xlabel + ' ' + p.x[0].toPrecision(3) + ' .. ' + p.x[nx - 1].toPrecision(3), m, H + 30);
    g.save(); g.translate(14, H); g.rotate(-Math.PI / 2);
    g.fillText(p.ylabel + ' ' + p.y[0].toPrecision(3) + ' .. ' + p.y[ny - 1].toPrecision(3), 0, 0); g.restore();
    for (let k = 0; k <= 10; k++) {
      g.fillStyle = col(lo + (hi - lo) * k / 10); g.fillRect(m + W + 15, H - (k + 1) * H / 11, 20, H / 11);
    }
    g.fillStyle = '#222'; g.fillText(hi.toPrecision(3), m + W + 38, 12); g.fillText(lo.toPrecision(3), m + W + 38, H - 2);
  }
  function nice(x) {
    const e = Math.pow(10, Math.floor(Math.log10(x))), f = x / e;
    return (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10) * e;
  }
  function scatter(el, p) {
    title(el, p);
    const W = Math.min(640, Math.max(400, el.clientWidth || 640)), H = 380, L = 64, R = 12, T = 10, B = 42;
    const cv = document.createElement('canvas'); cv.width = W; cv.height = H; el.appendChild(cv);
    const g = cv.getContext('2d');
    let x0 = 0, x1 = 0, ym = 0;  // the origin is always shown; the vertical range is symmetric (conjugate pairs)
    p.sets.forEach(s => s.x.forEach((v, i) => {
      if (v === null || s.y[i] === null) return;
      x0 = Math.min(x0, v); x1 = Math.max(x1, v); ym = Math.max(ym, Math.abs(s.y[i]));
    }));
    let dx = x1 - x0, dy = 2 * ym;
    if (!(dx > 0)) dx = dy > 0 ? dy : 1;
    if (!(dy > 0)) dy = dx;
    x0 -= 0.08 * dx; x1 += 0.08 * dx; const y0 = -0.54 * dy, y1 = 0.54 * dy;
    const px = v => L + (v - x0) / (x1 - x0) * (W - L - R), py = v => T + (y1 - v) / (y1 - y0) * (H - T - B);
    g.strokeStyle = '#888'; g.strokeRect(L, T, W - L - R, H - T - B);
    g.fillStyle = '#222'; g.font = '11px sans-serif'; g.textAlign = 'center';
    const sx = nice((x1 - x0) / 5), sy = nice((y1 - y0) / 5);
    for (let v = Math.ceil(x0 / sx) * sx; v <= x1; v += sx) g.fillText(+v.toPrecision(3), px(v), H - B + 14);
    g.textAlign = 'right';
    for (let v = Math.ceil(y0 / sy) * sy; v <= y1; v += sy) g.fillText(+v.toPrecision(3), L - 4, py(v) + 4);
    g.textAlign = 'center'; g.fillText(p.xlabel, L + (W - L - R) / 2, H - 6);
    g.save(); g.translate(12, T + (H - T - B) / 2); g.rotate(-Math.PI / 2); g.fillText(p.ylabel, 0, 0); g.restore();
    g.strokeStyle = '#bbb'; g.setLineDash([4, 3]); g.beginPath();
    g.moveTo(px(0), T); g.lineTo(px(0), H - B); g.moveTo(L, py(0)); g.lineTo(W - R, py(0)); g.stroke(); g.setLineDash([]);
    const legend = document.createElement('div'); legend.className = 'legend';
    const pale = ['rgba(31,119,180,0.3)', 'rgba(214,39,40,0.3)'];
    let c = 0, l = 0;
    p.sets.forEach(function (s) {
      const col = s.light ? pale[(l++) % pale.length] : colors[(c++) % colors.length];
      g.strokeStyle = col; g.fillStyle = col; g.lineWidth = s.light ? 1 : 2;
      s.x.forEach(function (v, i) {
        if (v === null || s.y[i] === null) return;
        const X = px(v), Y = py(s.y[i]), r = s.light ? 2 : 5;
        g.beginPath();
        if (s.marker === 'x') { g.moveTo(X - r, Y - r); g.lineTo(X + r, Y + r); g.moveTo(X - r, Y + r); g.lineTo(X + r, Y - r); g.stroke(); }
        else if (s.marker === 'o') { g.arc(X, Y, r, 0, 2 * Math.PI); g.stroke(); }
        else { g.arc(X, Y, r, 0, 2 * Math.PI); g.fill(); }
      });
      const item = document.createElement('span');
      item.textContent = (s.marker === 'x' ? '\u00d7 ' : s.marker === 'o' ? '\u25cb ' : '\u2022 ') + s.label;
      item.style.color = s.light ? col.replace('0.3)', '0.8)') : col; item.style.marginRight = '1.5em';
      legend.appendChild(item);
    });
    g.lineWidth = 1;
    el.appendChild(legend);
  }
  const kinds = { line: line, heatmap: heatmap, scatter: scatter };
  specs.forEach(function (p) {
    const el = document.getElementById(p.id);
    try { kinds[p.kind](el, p); } catch (e) { errors++; console.error(e); }
  });
  function check() {
    let drawn = 0;
    specs.forEach(function (p) {
      const cv = document.getElementById(p.id).querySelector('canvas');
      if (!cv || !cv.width || !cv.height) return;
      const px = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
      for (let i = 3; i < px.length; i += 4) if (px[i] !== 0) { drawn++; return; }
    });
    document.getElementById('ctid-selfcheck').textContent =
      'plots=' + specs.length + ' drawn=' + drawn + ' errors=' + errors;
  }
  // uPlot draws in a microtask; a timer runs after it (animation frames need not come in a headless browser).
  setTimeout(check, 0);
})();
)js";
  std::ostringstream body_;
  std::vector<std::string> specs_;
  int n_ = 0;
};

// Evenly decimated sample indices (at most max_points).
inline std::vector<Eigen::Index> keep(Eigen::Index n, int max_points) {
  const Eigen::Index stride = std::max<Eigen::Index>(1, (n + max_points - 1) / max_points);
  std::vector<Eigen::Index> k;
  for (Eigen::Index i = 0; i < n; i += stride) k.push_back(i);
  return k;
}
inline Eigen::VectorXd pick(const Eigen::VectorXd& v, const std::vector<Eigen::Index>& k) {
  Eigen::VectorXd o(static_cast<Eigen::Index>(k.size()));
  for (size_t i = 0; i < k.size(); ++i) o(static_cast<Eigen::Index>(i)) = v(k[i]);
  return o;
}

inline std::string fmt(double v, int digits = 6) {
  if (std::isnan(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

inline std::string input_name(const IdData& d, int i) {
  return i < static_cast<int>(d.input_names().size()) && !d.input_names()[static_cast<size_t>(i)].empty()
             ? d.input_names()[static_cast<size_t>(i)]
             : (d.nu() > 1 ? "u" + std::to_string(i + 1) : "u");
}

inline std::string output_name(const IdData& d, int j) {
  return j < static_cast<int>(d.output_names().size()) && !d.output_names()[static_cast<size_t>(j)].empty()
             ? d.output_names()[static_cast<size_t>(j)]
             : (d.ny() > 1 ? "y" + std::to_string(j + 1) : "y");
}

}  // namespace report_detail
}  // namespace ctid

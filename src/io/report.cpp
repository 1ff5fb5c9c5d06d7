// Self-contained HTML reports (see include/ctid/io/report.hpp). The page carries its plot data as JSON
// and draws it with the inlined uPlot; a self-check at the end of loading writes "plots=N drawn=M
// errors=E" into #ctid-selfcheck (drawn = canvases with at least one painted pixel; run from a timer after
// uPlot's drawing microtasks), which the browser test reads.
#include "ctid/io/report.hpp"

#include <algorithm>
#include <ctime>
#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include "ctid/core/check.hpp"
#include "ctid/estimate/gfrf.hpp"
#include "ctid/io/json.hpp"
#include "ctid/simulate/lsim.hpp"
#include "ctid/simulate/simulate.hpp"
#include "ctid/validate/compare.hpp"
#include "ctid/validate/metrics.hpp"
#include "ctid/validate/residuals.hpp"
#include "ctid/validate/uncertainty.hpp"

namespace ctid {

namespace report_assets {
extern const char* const kUplotJs;
extern const char* const kUplotCss;
extern const bool kHaveUplot;
}  // namespace report_assets

bool report_has_plot_library() { return report_assets::kHaveUplot; }

namespace {

std::string escape(const std::string& s) {
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

std::string json_string(const std::string& s) {
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

std::string js_number(double v, int digits = 6) {
  if (!std::isfinite(v)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string json_array(const Eigen::VectorXd& v) {
  std::string o = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i) o += ',';
    o += js_number(v(i));
  }
  return o + "]";
}

struct Series {
  std::string label;
  Eigen::VectorXd y;
  bool dashed = false;
  bool light = false;    // a band edge
  bool neutral = false;  // the measured signal among models (dark grey: the models keep their colours across plots)
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
        << ",\"y\":" << json_array(p.series[i].y) << "}";
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
std::vector<Eigen::Index> keep(Eigen::Index n, int max_points) {
  const Eigen::Index stride = std::max<Eigen::Index>(1, (n + max_points - 1) / max_points);
  std::vector<Eigen::Index> k;
  for (Eigen::Index i = 0; i < n; i += stride) k.push_back(i);
  return k;
}
Eigen::VectorXd pick(const Eigen::VectorXd& v, const std::vector<Eigen::Index>& k) {
  Eigen::VectorXd o(static_cast<Eigen::Index>(k.size()));
  for (size_t i = 0; i < k.size(); ++i) o(static_cast<Eigen::Index>(i)) = v(k[i]);
  return o;
}

std::string fmt(double v, int digits = 6) {
  if (std::isnan(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string input_name(const IdData& d, int i) {
  return i < static_cast<int>(d.input_names().size()) && !d.input_names()[static_cast<size_t>(i)].empty()
             ? d.input_names()[static_cast<size_t>(i)]
             : (d.nu() > 1 ? "u" + std::to_string(i + 1) : "u");
}

std::string output_name(const IdData& d, int j) {
  return j < static_cast<int>(d.output_names().size()) && !d.output_names()[static_cast<size_t>(j)].empty()
             ? d.output_names()[static_cast<size_t>(j)]
             : (d.ny() > 1 ? "y" + std::to_string(j + 1) : "y");
}

void data_section(Page& page, const IdData& d, const ReportOptions& o);

// The rows every report's summary ends with: the provenance (preprocessing, command line, data files, when given),
// the ctid version and commit, and the UTC time the report was made.
void provenance(std::vector<std::vector<std::string>>& rows, const ReportOptions& o) {
  for (const auto& [name, value] : o.provenance.rows()) rows.push_back({name, value});
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  char when[32] = "";
  if (gmtime_r(&now, &utc)) std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &utc);
  Provenance p = o.provenance;
  if (p.version.empty()) p = make_provenance();
  rows.push_back({"made by", p.made_by() + ", " + when});
}

template <class M>
void overview(Page& page, const IdData& d, const Result<M>& r, const ReportOptions& o, const std::string& model_text) {
  page.section("Summary");
  page.text("Model: <code>" + escape(model_text) + "</code>");
  std::vector<std::vector<std::string>> rows = {
      {"method", o.method.empty() ? "-" : o.method},
      {"termination", std::string(to_string(r.summary.termination)) +
                          (r.summary.message.empty() ? "" : " (" + r.summary.message + ")")},
      {"usable", r.usable() ? "yes" : "no: " + r.why_not_usable()},
      {"iterations", std::to_string(r.summary.iterations)},
      {"time", fmt(r.summary.seconds, 3) + " s"},
      {"fit (simulation)", r.fit.n_samples > 0 ? fmt(r.fit.fit_percent, 4) + " %" : std::string("not computed")},
      {"MSE / AIC / BIC", fmt(r.fit.mse, 4) + " / " + fmt(r.fit.aic, 5) + " / " + fmt(r.fit.bic, 5)},
      {"condition number", fmt(r.diagnostics.condition_number, 3)}};
  provenance(rows, o);
  page.table({"", ""}, rows);
  if (!o.settings.empty()) {
    std::vector<std::vector<std::string>> s;
    for (const auto& [k, v] : o.settings) s.push_back({k, v});
    page.section("Method settings");
    page.table({"setting", "value"}, s);
  }
  if (!r.diagnostics.choices.empty()) {
    page.section("Automatic choices");
    for (const auto& c : r.diagnostics.choices) page.text(escape(c));
  }
  if (!r.diagnostics.warnings.empty()) {
    page.section("Warnings");
    for (const auto& w : r.diagnostics.warnings) page.text("<span class=\"warn\">" + escape(w) + "</span>");
  }
  data_section(page, d, o);
}

// The record: its source, size, sampling and channels, and plots of its inputs and outputs.
void data_section(Page& page, const IdData& d, const ReportOptions& o) {
  page.section("Data");
  const double dur = d.duration();
  std::string inputs;
  for (int i = 0; i < d.nu(); ++i)
    inputs += (i ? ", " : "") + input_name(d, i) + " (" + to_string(d.intersample(i)) + ")";
  std::string outputs;
  for (int j = 0; j < d.ny(); ++j) outputs += (j ? ", " : "") + output_name(d, j);
  page.table({"", ""}, {{"source", o.data_source.empty() ? "-" : o.data_source},
                        {"samples", std::to_string(d.size())},
                        {"sampling", d.is_uniform() ? "Ts = " + fmt(d.ts()) + " s" : "irregular"},
                        {"duration", fmt(dur) + " s"},
                        {d.nu() > 1 ? "inputs" : "input", inputs},
                        {d.ny() > 1 ? "outputs" : "output", outputs}});
  const auto k = keep(d.size(), o.max_points);
  const Eigen::VectorXd t = pick(d.times(), k);
  std::vector<Series> us;
  for (int i = 0; i < d.nu(); ++i) us.push_back({input_name(d, i), pick(d.u().col(i), k)});
  page.plot({d.nu() > 1 ? "Inputs" : "Input", "time (s)", "u", t, us});
  std::vector<Series> ys;
  for (int j = 0; j < d.ny(); ++j) ys.push_back({output_name(d, j), pick(d.y().col(j), k)});
  page.plot({d.ny() > 1 ? "Outputs" : "Output", "time (s)", "y", t, ys});
}

// Method-specific numbers (the declared diagnostics the fit reported, with their units and meanings), e.g.
// SRIVC's delay, the LSSVF filter constant, KIA's GLS iterations, and the modal-function diagnostics (condition of
// each order's regression).
void diagnostics(Page& page, const Diagnostics& g) {
  std::vector<std::vector<std::string>> rows;
  auto row = [&](const std::string& name, const std::string& value) {
    const DiagnosticInfo* d = find_diagnostic(name);
    rows.push_back({name, value, d ? d->unit : "", d ? d->doc : ""});
  };
  for (const auto& [k, v] : g.scalars()) row(k, fmt(v));
  for (const auto& [k, v] : g.vectors()) {
    if (v.size() == 0 || v.size() > 24) continue;
    std::string s;
    for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt(v(i), 4);
    row(k, s);
  }
  if (rows.empty()) return;
  page.section("Diagnostics");
  if (g.has(diagnostic::condition_by_order)) {
    const Eigen::VectorXd& cond = g.get(diagnostic::condition_by_order);
    page.text("Modal functions (El-Shafey): condition_by_order is the condition number of the modal regression of each "
              "order j = 0, 1, .. (large values: the shifts or windows do not separate the modes; the estimate of that "
              "order is unreliable).");
    Eigen::VectorXd j = Eigen::VectorXd::LinSpaced(cond.size(), 0, static_cast<double>(cond.size() - 1));
    page.plot({"Modal regressions: log10 of the condition number by order", "order j", "log10 condition", j,
               {{"log10 cond", cond.array().log10().matrix()}}, false, true});
  }
  page.table({"diagnostic", "value", "unit", "meaning"}, rows);
}

void parameters(Page& page, const ParameterSet& p, const Eigen::VectorXd* err = nullptr) {
  page.section("Parameters");
  std::vector<std::vector<std::string>> rows;
  for (int i = 0; i < p.size(); ++i) {
    const bool fixed = i < static_cast<int>(p.fixed.size()) && p.fixed[static_cast<size_t>(i)];
    std::vector<std::string> r = {p.names[static_cast<size_t>(i)], fmt(p.values(i)),
                                  fixed ? "fixed" : (i < p.std.size() ? fmt(p.std(i), 3) : "-")};
    if (err) r.push_back(i < err->size() ? fmt((*err)(i), 4) : "-");
    rows.push_back(r);
  }
  // A parameter within two standard deviations of 0 is not significant: the data cannot tell it from 0 (at about 95 %),
  // so the structure may have a term too many.
  int insignificant = 0;
  for (int i = 0; i < p.size(); ++i) {
    const bool fixed = i < static_cast<int>(p.fixed.size()) && p.fixed[static_cast<size_t>(i)];
    const bool known = !fixed && i < p.std.size() && std::isfinite(p.std(i));
    const bool weak = known && std::abs(p.values(i)) < 2 * p.std(i);
    insignificant += weak;
    rows[static_cast<size_t>(i)].push_back(!known ? "-" : weak ? "no: |value| < 2 std" : "yes");
  }
  if (err) page.table({"parameter", "value", "std", "ERR %", "significant"}, rows);
  else page.table({"parameter", "value", "std", "significant"}, rows);
  if (insignificant > 0)
    page.text("<span class=\"warn\">" + std::to_string(insignificant) + " parameter(s) lie within two standard deviations "
              "of 0: the data cannot tell them from 0 (about 95 % confidence); a structure with fewer terms may do as "
              "well (compare its BIC).</span>");
}

// Measured vs simulated output and the residual correlation tests.
void validation(Page& page, const IdData& d, const Eigen::VectorXd& yhat, const ReportOptions& o, int out = 0) {
  const std::string of = d.ny() > 1 ? " (" + output_name(d, out) + ")" : "";
  page.section("Measured and simulated output" + of);
  const Eigen::VectorXd y = d.y().col(out);
  const auto k = keep(d.size(), o.max_points);
  Eigen::VectorXd e = y - yhat;
  const double fit = fit_report_or_inf(y, yhat, 0).fit_percent;
  page.plot({"Output" + of + ": measured and simulated (fit " + fmt(fit, 4) + " %)", "time (s)", "y", pick(d.times(), k),
             {{"measured", pick(y, k)}, {"simulated", pick(yhat, k)}}});
  if (!std::isfinite(e.squaredNorm())) {  // non-finite, or so large that the squares overflow
    page.text("<span class=\"warn\">The simulation does not stay finite on this record: no residual tests.</span>");
    return;
  }
  page.section("Residual tests" + of);
  const int lags = std::min(o.max_lag, d.size() / 4);
  if (lags < 1 || e.squaredNorm() == 0) {
    page.text("Too few samples or zero residuals: no correlation tests.");
    return;
  }
  std::vector<std::pair<std::string, CorrelationTest>> tests = {{"Residual autocorrelation", residual_autocorrelation(e, lags)}};
  for (int i = 0; i < d.nu(); ++i)
    tests.push_back({"Input-residual cross-correlation" + (d.nu() > 1 ? " (" + input_name(d, i) + ")" : std::string()),
                     input_residual_crosscorrelation(d.u().col(i), e, lags)});
  for (size_t t = 0; t < tests.size(); ++t) {
    const auto& [title, test] = tests[t];
    const CorrelationTest* c = &test;
    const Eigen::VectorXd x = c->lags.cast<double>();
    const Eigen::VectorXd b = Eigen::VectorXd::Constant(x.size(), c->bound);
    page.plot({title + ": " + std::to_string(c->n_outside) + " lag(s) outside the 99 % bounds",
               "lag (samples)", "correlation", x, {{"r(k)", c->values}, {"+bound", b, true, true}, {"-bound", -b, true, true}}, false,
               true});
    // What the result means, in one line (Ljung 1999, sec. 16.6).
    const bool pass = c->passed();
    const std::string meaning =
        t == 0 ? (pass ? "Passed: the residuals look white — nothing predictable is left in them."
                       : "Failed: the residuals are correlated — the model misses dynamics, or the noise is coloured "
                         "(an output-error fit does not model the noise; its parameters can still be right).")
               : (pass ? "Passed: the residuals do not depend on past inputs — no input-output dynamics is left "
                         "unexplained."
                       : "Failed: the residuals depend on the input — the model misses input-output dynamics (a higher "
                         "order, another delay, a nonlinearity), or the data were taken in closed loop.");
    page.text(pass ? meaning : "<span class=\"warn\">" + meaning + "</span>");
  }
}

// validation() of every output of the simulation yhat (N x ny).
void validations(Page& page, const IdData& d, const Eigen::MatrixXd& yhat, const ReportOptions& o) {
  for (int j = 0; j < d.ny(); ++j) validation(page, d, yhat.col(j), o, j);
}

// Bode magnitude and (unwrapped) phase of one or more responses hs = {(label, H(jw))} on the grid w; the
// 95 % magnitude band (lo_mag, hi_mag) goes with a single response.
// The phase of h in degrees, unwrapped along the grid (no jumps of 360).
Eigen::VectorXd unwrapped_phase_deg(const Eigen::VectorXcd& h) {
  Eigen::VectorXd ph(h.size());
  double prev = 0, offset = 0;
  for (Eigen::Index i = 0; i < h.size(); ++i) {
    const double a = std::arg(h(i)) * 180 / std::numbers::pi;
    if (i > 0) {
      while (a + offset - prev > 180) offset -= 360;
      while (a + offset - prev < -180) offset += 360;
    }
    ph(i) = prev = a + offset;
  }
  return ph;
}

// 95 % bands (2.5 and 97.5 % curves) of one response, each a (lower, upper) pair.
struct Bands {
  const MagnitudeBand* magnitude = nullptr;  ///< of |G(jw)|
  const MagnitudeBand* phase = nullptr;      ///< of the unwrapped phase, degrees
};

void bode(Page& page, const Eigen::VectorXd& w, const std::vector<std::pair<std::string, Eigen::VectorXcd>>& hs,
          const Bands& bands = {}) {
  page.section("Frequency response");
  std::vector<Series> ms, ps;
  for (const auto& [label, h] : hs) {
    ms.push_back({"|" + label + "|", (20 * h.cwiseAbs().array().log10()).matrix()});
    ps.push_back({hs.size() > 1 ? label : "phase", unwrapped_phase_deg(h)});
  }
  const MagnitudeBand* m = bands.magnitude && !bands.magnitude->empty() ? bands.magnitude : nullptr;
  const MagnitudeBand* p = bands.phase && !bands.phase->empty() ? bands.phase : nullptr;
  if (m) {
    ms.push_back({"2.5 %", (20 * m->lower.array().log10()).matrix(), false, true});
    ms.push_back({"97.5 %", (20 * m->upper.array().log10()).matrix(), false, true});
  }
  if (p) {
    ps.push_back({"2.5 %", p->lower, false, true});
    ps.push_back({"97.5 %", p->upper, false, true});
  }
  page.plot({"Bode magnitude" + std::string(m ? " with the 95 % band from the parameter covariance" : ""),
             "frequency (rad/s)", "dB", w, ms, true});
  page.plot({"Bode phase" + std::string(p ? " with the 95 % band from the parameter covariance" : ""),
             "frequency (rad/s)", "deg", w, ps, true});
}

// Step and impulse responses of a linear model (one curve per input, labelled) over `horizon` seconds; with `tf`, the
// 95 % band of the step response from its parameter covariance (response_band).
void time_responses(Page& page, const AnyModel& model, const std::vector<std::string>& labels, double horizon,
                    const Result<TransferFunction>* tf = nullptr) {
  page.section("Step and impulse responses");
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, horizon);
  const Eigen::MatrixXd s = model_step_response(model, t), g = model_impulse_response(model, t);
  std::vector<Series> step, impulse;
  for (Eigen::Index i = 0; i < s.cols(); ++i) {
    step.push_back({s.cols() > 1 ? labels[static_cast<size_t>(i)] : "step", s.col(i)});
    impulse.push_back({s.cols() > 1 ? labels[static_cast<size_t>(i)] : "impulse", g.col(i)});
  }
  const MagnitudeBand band =
      tf ? response_band(*tf, [&](const TransferFunction& m) { return step_response(m, t); }) : MagnitudeBand{};
  if (!band.empty()) {
    step.push_back({"2.5 %", band.lower, false, true});
    step.push_back({"97.5 %", band.upper, false, true});
  }
  page.plot({band.empty() ? "Step response" : "Step response with the 95 % band from the parameter covariance",
             "time (s)", "y", t, step});
  page.plot({"Impulse response", "time (s)", "y", t, impulse});
}

double nyquist_or_zero(const IdData& d) { return d.is_uniform() ? std::numbers::pi / d.ts() : 0.0; }

// The model simulated on a record for `purpose` (simulate/simulate.hpp: the library's one rule for the initial
// state), from the report's initial condition when it sets one; a diverging simulation is drawn up to where it
// stops being finite, with the reason.
Eigen::MatrixXd simulated(Page& page, const IdData& d, const Result<AnyModel>& r, SimulationPurpose purpose,
                          std::optional<InitialCondition> initial) {
  const SimulateOptions so = simulate_options(r, purpose, initial);
  const Simulation s = simulate(r.model, d, so);
  page.text("Simulated from the initial condition: " + std::string(to_string(so.initial)) + ".");
  if (!s.ok()) page.text("<span class=\"warn\">" + escape(s.problem) + "</span>");
  return s.y;
}

// The further records of ReportOptions::more_records, each in its own section: held-out records (more_records_initial
// set) as validation, the other records of a joint fit as the fit starts a record.
void more_records(Page& page, const Result<AnyModel>& r, const ReportOptions& o) {
  const AnyModel& m = r.model;
  for (size_t i = 0; i < o.more_records.size(); ++i) {
    const auto& [name, d] = o.more_records[i];
    CTID_REQUIRE(d.nu() == model_inputs(m) && d.ny() == model_outputs(m),
                 "html_report: record {} ({}) has {} input(s) and {} output(s); the model has {} and {}", i + 2, name,
                 d.nu(), d.ny(), model_inputs(m), model_outputs(m));
    page.section("Record " + std::to_string(i + 2) + ": " + name);
    page.text(std::to_string(d.size()) + " samples, " + fmt(d.duration()) + " s.");
    const auto y = o.more_records_initial ? simulated(page, d, r, SimulationPurpose::Validation, o.more_records_initial)
                                          : simulated(page, d, r, SimulationPurpose::OtherRecord, o.initial);
    validations(page, d, y, o);
  }
}

void require_siso(const IdData& d) {
  CTID_REQUIRE(d.nu() == 1 && d.ny() == 1, "html_report: needs one input and one output (got {}, {})", d.nu(), d.ny());
}

// What every report opens with: the summary, then (where the model describes the system) its simulation on the
// record and on each further record.
template <class M>
void opening(Page& page, const IdData& d, const Result<M>& r, const ReportOptions& o, bool simulate_on_records = true) {
  overview(page, d, r, o, describe(r.model));
  if (!simulate_on_records) return;
  const Result<AnyModel> any{AnyModel(r.model), {}, {}, {}, r.diagnostics};
  validations(page, d, simulated(page, d, any, SimulationPurpose::OwnFit, o.initial), o);
  more_records(page, any, o);
}

// A nonlinear model's response from rest to a step of the input's RMS level (it depends on the amplitude).
void step_at_input_level(Page& page, const AnyModel& m, const IdData& d, const Eigen::VectorXd& t) {
  page.section("Step response");
  const Eigen::VectorXd u = d.u().col(0);
  const double level = std::sqrt(u.squaredNorm() / std::max<Eigen::Index>(1, u.size()));
  try {
    page.plot({"Response to a step of the input's RMS level (" + fmt(level, 3) + ")", "time (s)", "y", t,
               {{"step", model_step_response(m, t, level).col(0)}}});
  } catch (const InvalidArgument& e) {
    page.text("<span class=\"warn\">" + escape(e.what()) + "</span>");
  }
}


// The poles of a transfer function as an engineer reads them: natural frequency and damping of each complex pair,
// time constant of each real pole, and the zeros, DC gain and delay.
void poles_and_gain(Page& page, const TransferFunction& g) {
  page.section("Poles, zeros and gain");
  std::vector<std::vector<std::string>> rows;
  const Eigen::VectorXcd p = g.poles();
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    const std::complex<double> s = p(i);
    if (s.imag() < -1e-12 * std::abs(s)) continue;  // a pair is shown once, by its upper pole
    const double wn = std::abs(s);
    const bool real = std::abs(s.imag()) <= 1e-12 * std::max(wn, 1e-300);
    const std::string where = s.real() > 0 ? "unstable" : s.real() == 0 ? "on the imaginary axis" : "stable";
    if (real)
      rows.push_back({fmt(s.real()), "real", s.real() != 0 ? fmt(1.0 / std::abs(s.real()), 4) + " s" : "-", "-", "-", where});
    else
      rows.push_back({fmt(s.real()) + " ± " + fmt(s.imag()) + "j", "complex pair", "-", fmt(wn, 4) + " rad/s (" +
                      fmt(wn / (2 * std::numbers::pi), 4) + " Hz)", fmt(-s.real() / wn, 4), where});
  }
  page.table({"pole", "kind", "time constant", "natural frequency", "damping ratio", ""}, rows);
  std::string zeros;
  const Eigen::VectorXcd z = g.zeros();
  for (Eigen::Index i = 0; i < z.size(); ++i)
    zeros += (i ? ", " : "") + (std::abs(z(i).imag()) > 0 ? fmt(z(i).real()) + (z(i).imag() > 0 ? "+" : "-") +
                                                                 fmt(std::abs(z(i).imag())) + "j"
                                                           : fmt(z(i).real()));
  page.table({"", ""}, {{"zeros", zeros.empty() ? "none" : zeros},
                        {"DC gain G(0)", fmt(g.dc_gain(), 5)},
                        {"delay", fmt(g.io_delay(), 4) + " s"}});
}

// The real and imaginary parts of v as a point set.
PointSet points(const std::string& label, const Eigen::VectorXcd& v, char marker, bool light = false) {
  return {label, v.real(), v.imag(), marker, light};
}

// Pole-zero map of a transfer-function fit with the poles and zeros of 200 models drawn from its parameter covariance
// (drawn_models, seeded) as a cloud: where the cloud is wide the data pin that pole or zero down poorly. The map shows
// the dynamics: it reaches 5 times the largest pole magnitude (the zeros' when there is no pole); estimated zeros
// beyond it are listed under the map, and the drawn points beyond it counted.
void pole_zero_map(Page& page, const Result<TransferFunction>& r) {
  const Eigen::VectorXcd p = r.model.poles(), z = r.model.zeros();
  double reach = 0;
  for (const auto& v : {p, z})
    if (reach == 0)
      for (Eigen::Index i = 0; i < v.size(); ++i) reach = std::max(reach, 5 * std::abs(v(i)));
  auto inside = [&](std::complex<double> x) { return std::isfinite(std::abs(x)) && std::abs(x) <= std::max(reach, 1e-300); };
  auto kept = [&](const Eigen::VectorXcd& v, int* left_out) {
    std::vector<std::complex<double>> o;
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (inside(v(i))) o.push_back(v(i));
      else if (left_out) ++*left_out;
    return o;
  };
  auto vec = [](const std::vector<std::complex<double>>& v) {
    return Eigen::Map<const Eigen::VectorXcd>(v.data(), static_cast<Eigen::Index>(v.size())).eval();
  };
  const std::vector<TransferFunction> draws = drawn_models(r);
  std::vector<std::complex<double>> dp, dz;
  int left_out = 0;
  for (const TransferFunction& g : draws) {
    for (const auto& x : kept(g.poles(), &left_out)) dp.push_back(x);
    for (const auto& x : kept(g.zeros(), &left_out)) dz.push_back(x);
  }
  std::vector<PointSet> sets;
  if (!draws.empty()) {
    sets.push_back(points("poles of " + std::to_string(draws.size()) + " models drawn from the covariance", vec(dp), '.', true));
    if (!dz.empty()) sets.push_back(points("their zeros", vec(dz), '.', true));
  }
  sets.push_back(points("poles", p, 'x'));
  const std::vector<std::complex<double>> zi = kept(z, nullptr);
  if (!zi.empty()) sets.push_back(points("zeros", vec(zi), 'o'));
  page.scatter({draws.empty() ? "Pole-zero map" : "Pole-zero map with the spread of the parameter covariance",
                "real part (1/s)", "imaginary part (rad/s)", sets});
  std::string note;
  if (!draws.empty())
    note = "The pale clouds show where the poles and zeros of equally likely models lie (drawn from the parameter "
           "covariance): a wide cloud is a pole or zero the data pin down poorly; a zero cloud over a pole cloud "
           "suggests they cancel and the order may be too high.";
  std::string far;
  for (Eigen::Index i = 0; i < z.size(); ++i)
    if (!inside(z(i)) && z(i).imag() >= 0)
      far += (far.empty() ? "" : ", ") + fmt(z(i).real(), 4) + (z(i).imag() > 0 ? " ± " + fmt(z(i).imag(), 4) + "j" : "");
  if (!far.empty()) note += " Zero(s) beyond the map (5 times the largest pole): " + far + ".";
  if (left_out) note += " " + std::to_string(left_out) + " drawn point(s) beyond the map are not shown.";
  if (!note.empty()) page.text(note);
}

std::string report_of(const IdData& d, const Result<TransferFunction>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  opening(page, d, r, o);
  poles_and_gain(page, r.model);
  pole_zero_map(page, r);
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  const Eigen::VectorXd w = frequency_grid(r.model.poles(), nyquist_or_zero(d));
  const Eigen::VectorXcd h = r.model.frequency_response(w);
  // 95 % bands of |G|, its phase and the step response from 200 draws of the parameter covariance (seeded: the
  // report is reproducible).
  const MagnitudeBand mag = magnitude_band(r, w);
  // Each drawn phase is unwrapped from the estimate's branch at the first frequency (a draw starting at -179 deg
  // against the estimate's +179 deg is the same curve, not one 360 deg away).
  const Eigen::VectorXd phase0 = unwrapped_phase_deg(h);
  const MagnitudeBand phase = response_band(r, [&](const TransferFunction& g) {
    Eigen::VectorXd ph = unwrapped_phase_deg(g.frequency_response(w));
    if (ph.size() > 0) ph.array() += 360.0 * std::round((phase0(0) - ph(0)) / 360.0);
    return ph;
  });
  bode(page, w, {{"G(jw)", h}}, {&mag, &phase});
  time_responses(page, r.model, {"G"}, response_horizon({r.model}, d.duration()), &r);
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

// A state-space model with any number of inputs and outputs: each output simulated and tested, the singular values of
// its subspace step, the poles with natural frequency, damping (and their standard deviations where the fit has a
// covariance) and mode shapes, the Bode magnitude of every channel, step responses per input.
std::string report_of(const IdData& d, const Result<StateSpace>& r, const ReportOptions& o) {
  const StateSpace& m = r.model;
  CTID_REQUIRE(d.nu() == m.nu() && d.ny() == m.ny(), "html_report: the model has {} inputs and {} outputs (data: {}, {})",
               m.nu(), m.ny(), d.nu(), d.ny());
  Page page;
  opening(page, d, r, o);
  if (r.diagnostics.has(diagnostic::singular_values)) {
    const Eigen::VectorXd& sv = r.diagnostics.get(diagnostic::singular_values);
    page.section("Singular values of the subspace step");
    page.text("The order is where they drop (relative to the largest, log10); the model has " + std::to_string(m.nx()) +
              " states.");
    const Eigen::VectorXd n = Eigen::VectorXd::LinSpaced(sv.size(), 1, static_cast<double>(sv.size()));
    page.plot({"Singular values", "index", "log10 (s_i / s_1)", n,
               {{"log10 s", (sv / std::max(sv(0), 1e-300)).array().max(1e-300).log10().matrix()}}, false, true});
  }
  page.section("Modes");
  const std::vector<Mode> modes = m.modes();
  const bool with_std = r.diagnostics.has(diagnostic::mode_wn_std) &&
                        r.diagnostics.get(diagnostic::mode_wn_std).size() == static_cast<Eigen::Index>(modes.size());
  std::vector<std::string> header = {"pole (1/s)", "wn (rad/s)", "f (Hz)", "zeta"};
  if (with_std) header.insert(header.begin() + 2, "wn std"), header.push_back("zeta std");
  for (int j = 0; j < m.ny(); ++j) header.push_back("|shape| " + output_name(d, j));
  std::vector<std::vector<std::string>> rows;
  for (size_t k = 0; k < modes.size(); ++k) {
    const Mode& md = modes[k];
    std::vector<std::string> row = {fmt(md.pole.real(), 5) + (md.pole.imag() != 0 ? " ± " + fmt(md.pole.imag(), 5) + "j" : ""),
                                    fmt(md.wn, 5), fmt(md.wn / (2 * std::numbers::pi), 5), fmt(md.zeta, 4)};
    if (with_std) {
      row.insert(row.begin() + 2, fmt(r.diagnostics.get(diagnostic::mode_wn_std)(static_cast<Eigen::Index>(k)), 3));
      row.push_back(fmt(r.diagnostics.get(diagnostic::mode_zeta_std)(static_cast<Eigen::Index>(k)), 3));
    }
    for (Eigen::Index j = 0; j < md.shape.size(); ++j) row.push_back(fmt(std::abs(md.shape(j)), 3));
    rows.push_back(row);
  }
  page.text("Mode shape: the output direction C v of the mode's eigenvector (unit norm).");
  page.table(header, rows);
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  // The Bode magnitude matrix: one plot per input, one curve per output.
  const Eigen::VectorXd w = frequency_grid(m.poles(), nyquist_or_zero(d));
  const std::vector<Eigen::MatrixXcd> G = frequency_response(m, w);
  page.section("Frequency response (magnitude of every channel)");
  for (int i = 0; i < m.nu(); ++i) {
    std::vector<Series> ms;
    for (int j = 0; j < m.ny(); ++j) {
      Eigen::VectorXd mag(w.size());
      for (Eigen::Index k = 0; k < w.size(); ++k) mag(k) = 20 * std::log10(std::abs(G[static_cast<size_t>(k)](j, i)));
      ms.push_back({output_name(d, j), mag});
    }
    page.plot({"Bode magnitude from " + input_name(d, i), "frequency (rad/s)", "dB", w, ms, true});
  }
  page.section("Step responses");
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, poles_response_horizon(m.poles(), d.duration()));
  const std::vector<Eigen::MatrixXd> steps = step_response(m, t);
  for (int i = 0; i < m.nu(); ++i) {
    std::vector<Series> ss;
    for (int j = 0; j < m.ny(); ++j) ss.push_back({output_name(d, j), steps[static_cast<size_t>(i)].col(j)});
    page.plot({"Unit step on " + input_name(d, i), "time (s)", "y", t, ss});
  }
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<MisoModel>& r, const ReportOptions& o) {
  CTID_REQUIRE(d.ny() == 1 && d.nu() == r.model.nu(), "html_report: the model has {} inputs and 1 output (data: {}, {})",
               r.model.nu(), d.nu(), d.ny());
  Page page;
  opening(page, d, r, o);
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  std::vector<std::string> labels;
  for (int i = 0; i < r.model.nu(); ++i) labels.push_back("G" + std::to_string(i + 1) + " (" + input_name(d, i) + ")");
  const Eigen::VectorXd w = frequency_grid(model_poles(r.model), nyquist_or_zero(d));
  const Eigen::MatrixXcd h = model_frequency_response(r.model, w);
  std::vector<std::pair<std::string, Eigen::VectorXcd>> hs;
  for (int i = 0; i < r.model.nu(); ++i) hs.push_back({labels[static_cast<size_t>(i)], h.col(i)});
  bode(page, w, hs);
  time_responses(page, r.model, labels, response_horizon(r.model.channels, d.duration()));
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<FsfModel>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  const FsfModel& m = r.model;
  opening(page, d, r, o, m.shift() == 0.0);
  if (m.shift() != 0.0)
    page.text("The model was fitted to exponentially windowed data (a = " + fmt(m.shift()) +
              " 1/s): it describes G(s + a), not the system, and is not simulated against the record.");
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  page.section("Compressed responses (Gawthrop & Wang): +-2 std bands from the parameter covariance");
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(400, 0.0, m.T());
  const Eigen::VectorXd s = m.step_response(t), ss = m.step_response_std(t);
  const Eigen::VectorXd g = m.impulse_response(t), gs = m.impulse_response_std(t);
  const bool bands = ss.allFinite();
  std::vector<Series> sv = {{"step", s}}, gv = {{"impulse", g}};
  if (bands) {
    sv.push_back({"-2 std", s - 2 * ss, false, true});
    sv.push_back({"+2 std", s + 2 * ss, false, true});
    gv.push_back({"-2 std", g - 2 * gs, false, true});
    gv.push_back({"+2 std", g + 2 * gs, false, true});
  }
  page.plot({"Step response", "time (s)", "y", t, sv});
  page.plot({"Impulse response", "time (s)", "y", t, gv});
  const Eigen::VectorXd w = model_frequency_grid(m);
  bode(page, w, {{"Gbar(e^{jw Delta})", m.frequency_response(w)}});
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

// |H_2(j w1, j w2)| on a grid (w1, w2 in (0, wmax]) of a kernel function.
template <class F>
Heatmap h2_map(F h2, double wmax, const std::string& what) {
  const int n = 40;
  Heatmap m{"|H_2(jw1, jw2)| of the " + what + " (dB)", "w1 (rad/s)", "w2 (rad/s)", Eigen::VectorXd(n),
            Eigen::VectorXd(n), Eigen::MatrixXd(n, n)};
  for (int i = 0; i < n; ++i) m.x(i) = m.y(i) = wmax * (i + 1) / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double a = std::abs(h2(std::complex<double>(0, m.x(j)), std::complex<double>(0, m.y(i))));
      m.z(i, j) = a > 0 ? 20 * std::log10(a) : NAN;
    }
  return m;
}

std::string report_of(const IdData& d, const Result<NarxModel>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  const NarxModel p = r.model.process();
  opening(page, d, r, o);
  page.section("Selected terms");
  page.text("Terms in the order of selection by forward orthogonal least squares; ERR: the error reduction ratio "
            "(share of the output energy explained by the term).");
  parameters(page, r.parameters, r.diagnostics.has(diagnostic::err) ? &r.diagnostics.get(diagnostic::err) : nullptr);
  diagnostics(page, r.diagnostics);
  const bool zoh = d.intersample(0) == Intersample::Zoh;
  const double nyq = std::numbers::pi / p.ts();
  Eigen::VectorXd w = frequency_grid(Eigen::VectorXcd::Constant(1, std::complex<double>(0.1 * nyq, 0.0)), 0.9 * nyq);
  bool linear = false;
  for (const auto& t : p.terms()) linear = linear || (t.degree() == 1 && !t.has_noise());
  if (linear) {
    Eigen::VectorXcd h(w.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) h(i) = narx_gfrf_ct(p, {std::complex<double>(0, w(i))}, zoh);
    bode(page, w, {{"H_1(jw)", h}});
    if (p.degree() >= 2) {
      page.section("Second-order GFRF");
      page.heatmap(h2_map([&](auto a, auto b) { return narx_gfrf_ct(p, {a, b}, zoh); }, 0.5 * nyq, "NARX model"));
    }
  }
  step_at_input_level(page, p, d, time_grid(p.ts(), std::max(4 * std::min(p.max_lag(), d.size()), 200)));
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<NdeModel>& r, const ReportOptions& o) {
  require_siso(d);
  Page page;
  const NdeModel& m = r.model;
  opening(page, d, r, o);
  const Eigen::VectorXd* err = r.diagnostics.has(diagnostic::err) ? &r.diagnostics.get(diagnostic::err) : nullptr;
  parameters(page, r.parameters, err && err->size() == r.parameters.size() ? err : nullptr);
  diagnostics(page, r.diagnostics);
  const Eigen::VectorXd w = frequency_grid(m.a().roots(), nyquist_or_zero(d));
  Eigen::VectorXcd h(w.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) h(i) = m.h1(std::complex<double>(0, w(i)));
  bode(page, w, {{"H_1(jw)", h}});
  bool nonlinear = false;
  for (const auto& term : m.terms()) nonlinear = nonlinear || term.degree() == 2;
  if (nonlinear) {
    page.section("Second-order GFRF (harmonic probing)");
    page.heatmap(h2_map([&](auto a, auto b) { return m.h2(a, b); }, w(w.size() - 1) / 4, "equation"));
  }
  step_at_input_level(page, m, d,
                      Eigen::VectorXd::LinSpaced(400, 0.0, std::min(d.duration(), 20 * 2 * std::numbers::pi / w(w.size() / 2))));
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

std::string report_of(const IdData& d, const Result<GreyboxModel>& r, const ReportOptions& o) {
  CTID_REQUIRE(d.ny() == 1, "html_report: a grey-box report shows one output (the record has {})", d.ny());
  Page page;
  opening(page, d, r, o);
  page.section("Equations");
  page.text("<pre>" + escape(r.model.to_string()) + "</pre>");
  parameters(page, r.parameters);
  diagnostics(page, r.diagnostics);
  return page.render(o.title.empty() ? o.method + " fit" : o.title);
}

// The one-line meaning of a residual test result (Ljung 1999, sec. 16.6), for the table of a comparison.
std::string test_cell(const CorrelationTest& c) {
  if (c.lags.size() == 0) return "-";
  return c.passed() ? "passed" : std::to_string(c.n_outside) + " lag(s) outside";
}

}  // namespace

std::string html_comparison_report(const IdData& d, const std::vector<ModelComparison>& cs, const ReportOptions& o) {
  CTID_REQUIRE(!cs.empty(), "html_comparison_report: no model to compare");
  for (const ModelComparison& c : cs)
    CTID_REQUIRE(c.simulation.y.rows() == d.size() && c.simulation.y.cols() == d.ny() &&
                     static_cast<int>(c.fits.size()) == d.ny(),
                 "html_comparison_report: model {} was not compared on this record (compare_models)", c.name);
  Page page;
  const size_t best = best_comparison(cs);
  page.section("Summary");
  std::vector<std::vector<std::string>> rows = {
      {"models", std::to_string(cs.size())},
      {"best fit", cs[best].name + " (" + fmt(cs[best].mean_fit(), 4) + " %" + (d.ny() > 1 ? ", mean over the outputs)" : ")")}};
  provenance(rows, o);
  page.table({"", ""}, rows);

  page.section("Models");
  std::vector<std::string> header = {"model", "type", "coefficients", "initial condition"};
  for (int j = 0; j < d.ny(); ++j) header.push_back(d.ny() > 1 ? "fit % (" + output_name(d, j) + ")" : "fit %");
  header.insert(header.end(), {"NRMSE", "AIC"});
  std::vector<std::vector<std::string>> table;
  for (const ModelComparison& c : cs) {
    std::vector<std::string> r = {c.name, model_type_name(c.model), std::to_string(model_coefficient_count(c.model)),
                                  to_string(c.initial)};
    for (const FitReport& f : c.fits) r.push_back(std::isfinite(f.fit_percent) ? fmt(f.fit_percent, 4) : "diverges");
    r.push_back(fmt(c.mean_nrmse(), 4));
    r.push_back(fmt(c.total_aic(), 5));
    table.push_back(r);
  }
  page.table(header, table);
  page.text("Each model is simulated from its initial condition on the record (estimated: the state that fits the "
            "record's first samples best, as MATLAB's compare; measured: the record's own past outputs) and scored on "
            "the whole record. AIC counts each model's coefficients" + std::string(d.ny() > 1 ? ", summed over the outputs" : "") +
            ": lower is better for the same data.");
  for (const ModelComparison& c : cs) {
    page.text("<code>" + escape(c.name) + "</code>: " + escape(describe(c.model, 4)));
    if (!c.simulation.ok()) page.text("<span class=\"warn\">" + escape(c.name + ": " + c.simulation.problem) + "</span>");
  }
  data_section(page, d, o);

  const auto k = keep(d.size(), o.max_points);
  for (int j = 0; j < d.ny(); ++j) {
    const std::string of = d.ny() > 1 ? " (" + output_name(d, j) + ")" : "";
    page.section("Measured and simulated output" + of);
    std::vector<Series> series = {{"measured", pick(d.y().col(j), k), false, false, true}};
    for (const ModelComparison& c : cs)
      series.push_back({c.name + " (" + (std::isfinite(c.fits[static_cast<size_t>(j)].fit_percent)
                                             ? fmt(c.fits[static_cast<size_t>(j)].fit_percent, 4) + " %"
                                             : std::string("diverges")) + ")",
                        pick(c.simulation.y.col(j), k)});
    page.plot({"Output" + of + ": measured and each model's simulation", "time (s)", "y", pick(d.times(), k), series});
  }

  page.section("Residual tests");
  std::vector<std::string> th = {"model"};
  if (d.ny() > 1) th.push_back("output");
  th.push_back("whiteness");
  for (int i = 0; i < d.nu(); ++i) th.push_back("independence of " + input_name(d, i));
  std::vector<std::vector<std::string>> tests;
  for (const ModelComparison& c : cs)
    for (int j = 0; j < d.ny(); ++j) {
      std::vector<std::string> r = {c.name};
      if (d.ny() > 1) r.push_back(output_name(d, j));
      r.push_back(test_cell(c.whiteness[static_cast<size_t>(j)]));
      const auto& ind = c.independence[static_cast<size_t>(j)];
      for (int i = 0; i < d.nu(); ++i) r.push_back(i < static_cast<int>(ind.size()) ? test_cell(ind[static_cast<size_t>(i)]) : "-");
      tests.push_back(r);
    }
  page.table(th, tests);
  page.text("Whiteness fails: the residuals are correlated — the model misses dynamics, or the noise is coloured (an "
            "output-error model does not model the noise). Independence fails: the residuals depend on that input — "
            "the model misses input-output dynamics (order, delay, a nonlinearity), or the data are closed-loop. "
            "99 % bounds, lags up to " + std::to_string(std::min(o.max_lag, d.size() / 4)) + ".");

  // Responses of the models (one output: model_frequency_response and the step responses are of the first output).
  if (d.ny() != 1) {
    page.text("The frequency and step responses are compared for single-output records only.");
    return page.render(o.title.empty() ? "ctid compare" : o.title);
  }
  std::vector<const ModelComparison*> linear;
  std::vector<std::complex<double>> all_poles;
  for (const ModelComparison& c : cs) {
    if (!is_linear(c.model)) continue;
    try {
      (void)model_frequency_response(c.model, Eigen::VectorXd::Ones(1));
    } catch (const InvalidArgument& e) {  // a windowed FSF model
      page.text(escape(c.name + ": no frequency or step response (" + e.what() + ")"));
      continue;
    }
    linear.push_back(&c);
    const Eigen::VectorXcd p = model_poles(c.model);
    all_poles.insert(all_poles.end(), p.data(), p.data() + p.size());
  }
  const Eigen::VectorXcd poles = Eigen::Map<const Eigen::VectorXcd>(all_poles.data(), static_cast<Eigen::Index>(all_poles.size()));
  if (!linear.empty()) {
    const Eigen::VectorXd w = frequency_grid(poles, nyquist_or_zero(d));
    for (int i = 0; i < d.nu(); ++i) {
      const std::string from = d.nu() > 1 ? " from " + input_name(d, i) : "";
      std::vector<Series> mag, ph;
      for (const ModelComparison* c : linear) {
        const Eigen::VectorXcd h = model_frequency_response(c->model, w).col(i);
        mag.push_back({c->name, (20 * h.cwiseAbs().array().log10()).matrix()});
        ph.push_back({c->name, unwrapped_phase_deg(h)});
      }
      page.section("Frequency response" + from);
      page.plot({"Bode magnitude" + from + " (up to the record's Nyquist frequency)", "frequency (rad/s)", "dB", w, mag, true});
      page.plot({"Bode phase" + from, "frequency (rad/s)", "deg", w, ph, true});
    }
  }
  // Step responses: unit steps when every model is linear; otherwise every model's response to a step of each input's
  // RMS level (a nonlinear model's step response depends on the amplitude). A NARX model steps on its sampling grid.
  const bool all_linear = linear.size() == cs.size();
  double horizon = poles_response_horizon(poles, d.duration());
  Eigen::VectorXd t;
  if (d.is_uniform()) {
    const Eigen::Index n = std::min<Eigen::Index>(static_cast<Eigen::Index>(std::ceil(horizon / d.ts())), 20000);
    t = Eigen::VectorXd::LinSpaced(n + 1, 0.0, static_cast<double>(n)) * d.ts();
  } else {
    t = Eigen::VectorXd::LinSpaced(400, 0.0, horizon);
  }
  const auto kt = keep(t.size(), o.max_points);
  for (int i = 0; i < d.nu(); ++i) {
    const Eigen::VectorXd u = d.u().col(i);
    const double level = all_linear ? 1.0 : std::sqrt(u.squaredNorm() / std::max<Eigen::Index>(1, u.size()));
    std::vector<Series> steps;
    std::vector<std::string> failed;
    for (const ModelComparison& c : cs) {
      if (is_linear(c.model) && std::find(linear.begin(), linear.end(), &c) == linear.end()) continue;
      const Eigen::VectorXcd p = model_poles(c.model);
      if ((p.real().array() > 0).any()) {  // its growth would flatten every other curve
        if (i == 0) failed.push_back(c.name + ": not drawn, it is unstable (its step response grows without bound)");
        continue;
      }
      try {
        steps.push_back({c.name, pick(model_step_response(c.model, t, level).col(i), kt)});
      } catch (const InvalidArgument& e) {
        failed.push_back(c.name + ": " + e.what());
      }
    }
    const std::string from = d.nu() > 1 ? " of " + input_name(d, i) : "";
    page.section("Step response" + from);
    if (!steps.empty())
      page.plot({all_linear ? "Unit step response" + from
                            : "Response to a step" + from + " of the input's RMS level (" + fmt(level, 3) + ")",
                 "time (s)", "y", pick(t, kt), steps});
    for (const auto& f : failed) page.text("<span class=\"warn\">" + escape(f) + "</span>");
  }
  if (!linear.empty()) {
    page.section("Poles");
    std::vector<PointSet> sets;
    for (const ModelComparison* c : linear) sets.push_back(points(c->name, model_poles(c->model), 'x'));
    page.scatter({"Poles of the linear models", "real part (1/s)", "imaginary part (rad/s)", sets});
  }
  return page.render(o.title.empty() ? "ctid compare" : o.title);
}

std::string html_report(const IdData& data, const Result<AnyModel>& result, const ReportOptions& options) {
  return std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        return report_of(data, Result<M>{m, result.parameters, result.fit, result.summary, result.diagnostics},
                         options);
      },
      result.model);
}

}  // namespace ctid

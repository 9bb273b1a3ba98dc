#include "clumpkit/calibrate/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "clumpkit/core/atomic_file.hpp"

namespace clumpkit::calibrate {

namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else if (c == '"')
      o += "&quot;";
    else
      o += c;
  }
  return o;
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v =
        (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += t[v >> 18 & 63];
    out += t[v >> 12 & 63];
    out += t[v >> 6 & 63];
    out += t[v & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16;
    out += t[v >> 18 & 63];
    out += t[v >> 12 & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += t[v >> 18 & 63];
    out += t[v >> 12 & 63];
    out += t[v >> 6 & 63];
    out += '=';
  }
  return out;
}

std::string label(const Measurement& m) {
  const std::string s = m.setting_text();
  return fmt::format("{} {}{} {}", m.rig, m.sample, s.empty() ? "" : " [" + s + "]", m.quantity);
}

// Simulated against measured, one panel per quantity, error bars = 2 standard errors.
std::string scatter_svg(const Comparison& c) {
  std::map<std::string, std::vector<const ObservableComparison*>> byq;
  for (const auto& o : c.observables) byq[o.measured.quantity].push_back(&o);
  std::string out;
  for (const auto& [q, obs] : byq) {
    double lo = 1e300, hi = -1e300;
    for (const auto* o : obs) {
      const double em = 2 * o->measured.std / std::sqrt(o->measured.n);
      const double es = o->simulated.n > 1 ? 2 * o->simulated.std / std::sqrt(o->simulated.n) : 0;
      lo = std::min({lo, o->measured.value - em, o->simulated.mean - es});
      hi = std::max({hi, o->measured.value + em, o->simulated.mean + es});
    }
    const double pad = 0.08 * std::max(hi - lo, 1e-12 * std::abs(hi) + 1e-300);
    lo -= pad;
    hi += pad;
    const double W = 300, P = 45;
    auto X = [&](double v) { return P + (v - lo) / (hi - lo) * (W - 2 * P); };
    auto Y = [&](double v) { return W - P - (v - lo) / (hi - lo) * (W - 2 * P); };
    std::string s = fmt::format(
        "<svg class=\"plot\" width=\"{0}\" height=\"{0}\" viewBox=\"0 0 {0} {0}\" "
        "xmlns=\"http://www.w3.org/2000/svg\"><rect x=\"{1}\" y=\"{1}\" width=\"{2}\" "
        "height=\"{2}\" fill=\"#fafafa\" stroke=\"#999\"/>",
        W, P, W - 2 * P);
    s += fmt::format(
        "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"#888\" "
        "stroke-dasharray=\"4\"/>",
        X(lo), Y(lo), X(hi), Y(hi));
    for (const auto* o : obs) {
      const double x = X(o->measured.value), y = Y(o->simulated.mean);
      const double ex = X(o->measured.value + 2 * o->measured.std / std::sqrt(o->measured.n)) - x;
      const double ey =
          o->simulated.n > 1
              ? y - Y(o->simulated.mean + 2 * o->simulated.std / std::sqrt(o->simulated.n))
              : 0;
      const char* col = o->pass ? "#1b7f3b" : "#c62828";
      s += fmt::format("<g><title>{}: measured {:.4g}, simulated {:.4g}, z {:+.2f}</title>",
                       esc(label(o->measured)), o->measured.value, o->simulated.mean, o->z);
      s += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\"/>", x - ex, y,
                       x + ex, y, col);
      s += fmt::format("<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"{}\"/>", x, y - ey,
                       x, y + ey, col);
      s += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"4\" fill=\"{}\"/></g>", x, y, col);
    }
    const std::string unit = obs.front()->measured.unit;
    s += fmt::format(
        "<text x=\"{}\" y=\"{}\" font-size=\"12\" text-anchor=\"middle\">measured "
        "{} ({})</text>",
        W / 2, W - 10, esc(q), esc(unit));
    s += fmt::format(
        "<text x=\"12\" y=\"{}\" font-size=\"12\" text-anchor=\"middle\" "
        "transform=\"rotate(-90 12 {})\">simulated ({})</text>",
        W / 2, W / 2, esc(unit));
    s += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"10\">{:.4g}</text>", P, W - P + 12, lo);
    s += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"10\" text-anchor=\"end\">{:.4g}</text>",
                     W - P, W - P + 12, hi);
    out += s + "</svg>\n";
  }
  return out;
}

// z of every observable, grouped by rig and setting, with the |z| <= 2 band.
std::string residual_svg(const Comparison& c) {
  const double row = 18, left = 330, width = 300, zmax = 6;
  const double H = row * c.observables.size() + 40;
  std::string s = fmt::format(
      "<svg class=\"plot\" width=\"{}\" height=\"{}\" "
      "xmlns=\"http://www.w3.org/2000/svg\">",
      left + width + 20, H);
  auto X = [&](double z) {
    return left + (std::clamp(z, -zmax, zmax) + zmax) / (2 * zmax) * width;
  };
  s += fmt::format("<rect x=\"{}\" y=\"10\" width=\"{}\" height=\"{}\" fill=\"#e8f5e9\"/>", X(-2),
                   X(2) - X(-2), H - 30);
  s += fmt::format("<line x1=\"{0}\" y1=\"10\" x2=\"{0}\" y2=\"{1}\" stroke=\"#666\"/>", X(0),
                   H - 20);
  std::vector<const ObservableComparison*> obs;
  for (const auto& o : c.observables) obs.push_back(&o);
  std::stable_sort(obs.begin(), obs.end(), [](auto* a, auto* b) {
    return std::tie(a->measured.rig, a->measured.sample) <
           std::tie(b->measured.rig, b->measured.sample);
  });
  for (size_t i = 0; i < obs.size(); ++i) {
    const auto* o = obs[i];
    const double y = 14 + row * i;
    const char* col = o->pass ? "#1b7f3b" : "#c62828";
    s += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"end\">{}</text>",
                     left - 6, y + 11, esc(label(o->measured)));
    s += fmt::format(
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"><title>z = "
        "{:+.2f}</title></rect>",
        std::min(X(0), X(o->z)), y + 2, std::abs(X(o->z) - X(0)), row - 5, col, o->z);
  }
  for (int z = -6; z <= 6; z += 2)
    s += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"10\" text-anchor=\"middle\">{}</text>",
                     X(z), H - 6, z);
  return s + "</svg>\n";
}

std::string chain_svg(const std::vector<std::pair<std::string, Comparison>>& chain) {
  const double bar = 60, H = 220, B = 30;
  double vmax = 1.5;
  for (const auto& [n, c] : chain) vmax = std::max(vmax, c.chi2_per_dof);
  const double W = 60 + bar * 1.4 * chain.size();
  std::string s = fmt::format(
      "<svg class=\"plot\" width=\"{}\" height=\"{}\" xmlns=\"http://www.w3.org/2000/svg\">", W,
      H + 40);
  auto Y = [&](double v) { return H - v / vmax * (H - B); };
  s += fmt::format(
      "<line x1=\"40\" y1=\"{0}\" x2=\"{1}\" y2=\"{0}\" stroke=\"#1b7f3b\" "
      "stroke-dasharray=\"4\"/><text x=\"42\" y=\"{2}\" font-size=\"10\">1.5</text>",
      Y(1.5), W, Y(1.5) - 3);
  for (size_t i = 0; i < chain.size(); ++i) {
    const double x = 50 + i * bar * 1.4, v = chain[i].second.chi2_per_dof;
    s += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>", x, Y(v),
                     bar, H - Y(v), v <= 1.5 ? "#1b7f3b" : "#c62828");
    s +=
        fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\">{:.2f}</text>",
                    x + bar / 2, Y(v) - 4, v);
    s += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"11\" text-anchor=\"middle\">{}</text>",
                     x + bar / 2, H + 16, esc(chain[i].first));
  }
  return s + "</svg>\n";
}

}  // namespace

std::string report_html(const ReportInput& in) {
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" +
                  esc(in.title) +
                  "</title><style>body{font-family:sans-serif;margin:2em;max-width:1100px}"
                  "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;"
                  "text-align:right}td.l{text-align:left}tr.fail{background:#ffebee}"
                  ".plot{margin:6px;vertical-align:top}.verdict{font-size:1.2em;padding:8px;"
                  "background:#fff8e1;border-left:4px solid #f9a825}</style></head><body>\n";
  h += "<h1 id=\"title\">" + esc(in.title) + "</h1>\n";
  if (in.chain.empty()) return h + "<p>No comparison.</p></body></html>\n";
  const auto& [name, c] = in.chain.back();
  h += fmt::format(
      "<p id=\"summary\">Model <b>{}</b>: chi2 = {:.2f}, dof = {}, chi2/dof = "
      "<b>{:.2f}</b>; {} of {} observables within |z| &le; 2.</p>\n",
      esc(name), c.chi2, c.dof, c.chi2_per_dof,
      std::count_if(c.observables.begin(), c.observables.end(),
                    [](const auto& o) { return o.pass; }),
      c.observables.size());
  if (in.diagnosis) {
    h += "<h2>Diagnosis</h2>\n<pre class=\"verdict\" id=\"verdict\">" +
         esc(in.diagnosis->summary()) + "</pre>\n";
    h += "<table id=\"candidates\"><tr><th>effect</th><th>parameter</th><th>fitted</th><th>&plusmn;"
         "</th><th>95 % "
         "interval</th><th>chi2</th><th>&Delta;chi2</th><th>BIC</th><th>weight</th><th>plausible</"
         "th>"
         "<th>chi2 from</th></tr>\n";
    for (const auto& r : in.diagnosis->candidates)
      h += fmt::format(
          "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{:.3g}</td><td>{}</td>"
          "<td>{:.2f}</td><td>{:.2f}</td><td>{:.2f}</td><td>{:.3f}</td><td>{}</td>"
          "<td class=\"l\">{}</td></tr>\n",
          esc(r.candidate.effect), esc(parameter_text(r)), esc(r.candidate.format(r.fitted)),
          r.fitted_std, esc(interval_text(r)), r.comparison.chi2, r.delta_chi2, r.bic, r.weight,
          r.plausible  ? "yes"
          : r.at_limit ? "no (at limit)"
                       : "no",
          esc(chi2_source_text(r)));
    h += "</table>\n";
    if (std::any_of(in.diagnosis->candidates.begin(), in.diagnosis->candidates.end(),
                    [](const CandidateResult& r) { return r.interval_past_runs(); }))
      h += "<p class=\"limit\">" + esc(kIntervalPastRunsNote) + "</p>\n";
    for (const auto& r : in.diagnosis->candidates)
      if (!r.limit.empty())
        h += "<p class=\"limit\">" + esc(r.candidate.effect + ": " + r.limit) + "</p>\n";
  }
  h += "<h2>Observables</h2>\n<table id=\"observables\"><tr><th>rig</th><th>sample</th><th>setting"
       "</th><th>quantity</th><th>measured</th><th>&plusmn; std</th><th>simulated</th><th>&plusmn; "
       "std</th><th>unit</th><th>z</th><th>rel. error</th><th>pass</th></tr>\n";
  for (const auto& o : c.observables)
    h += fmt::format(
        "<tr class=\"{}\"><td class=\"l\">{}</td><td class=\"l\">{}</td><td "
        "class=\"l\">{}</td><td class=\"l\">{}</td><td>{:.4g}</td><td>{:.2g}</td><td>"
        "{:.4g}</td><td>{:.2g}</td><td class=\"l\">{}</td><td>{:+.2f}</td><td>{:+.1f} %"
        "</td><td>{}</td></tr>\n",
        o.pass ? "pass" : "fail", esc(o.measured.rig), esc(o.measured.sample),
        esc(o.measured.setting_text()), esc(o.measured.quantity), o.measured.value, o.measured.std,
        o.simulated.mean, o.simulated.std, esc(o.measured.unit), o.z, 100 * o.rel_error,
        o.pass ? "yes" : "<b>no</b>");
  h += "</table>\n<h2>Simulated against measured</h2>\n<p>Error bars: 2 standard errors of the "
       "mean; the dashed line is simulated = measured; red points fail (|z| &gt; 2).</p>\n<div "
       "id=\"scatter\">" +
       scatter_svg(c) + "</div>\n";
  h += "<h2>Residual pattern</h2>\n<p>z by rig and setting (green band: |z| &le; 2). A pattern "
       "that moves with a setting points to a missing effect, not a parameter.</p>\n<div "
       "id=\"residuals\">" +
       residual_svg(c) + "</div>\n";
  if (in.chain.size() > 1)
    h += "<h2>Model versions</h2>\n<p>chi2/dof per model version (dashed: 1.5).</p>\n<div "
         "id=\"chain\">" +
         chain_svg(in.chain) + "</div>\n";
  if (!in.pictures.empty()) {
    h += "<h2>Rig pictures</h2>\n<div id=\"pictures\">";
    for (const auto& p : in.pictures) {
      std::string data;
      try {
        data = read_file(p);
      } catch (const std::exception&) {
        continue;
      }
      h += "<figure style=\"display:inline-block\"><img style=\"max-width:520px\" alt=\"" +
           esc(p.filename().string()) + "\" src=\"data:image/png;base64," + base64(data) +
           "\"><figcaption>" + esc(p.filename().string()) + "</figcaption></figure>\n";
    }
    h += "</div>\n";
  }
  return h +
         "<p style=\"color:#777\">Written by clumpkit; self-contained, no "
         "network.</p></body></html>\n";
}

void write_report(const ReportInput& in, const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  write_file_atomic(dir / "index.html", report_html(in));
}

}  // namespace clumpkit::calibrate

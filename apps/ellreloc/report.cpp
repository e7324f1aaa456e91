// `ellreloc report`: one self-contained HTML file (no network, no external script) with the
// Table-I rows of every method, the comparison figure as inline SVG, the overlays of the first
// method's worst frames inlined as PNG, and every frame's errors in a table sortable by column.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

#include "commands.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"

namespace ellreloc::cli {

CLI::App* addReportCommand(CLI::App& app, ReportArgs& a) {
  CLI::App* r = app.add_subcommand("report", "one self-contained HTML page comparing methods: table, plots, overlays");
  r->add_option("--groundtruth", a.groundtruth, "TUM trajectory of the true camera poses")
      ->required()
      ->check(CLI::ExistingFile);
  r->add_option("--estimate", a.estimates,
                "TUM poses written by `ellreloc relocalize`, as FILE or FILE:LABEL; repeat it to compare methods")
      ->required();
  r->add_option("--detections", a.detections, "the query frames (default: every ground-truth pose)")
      ->check(CLI::ExistingFile);
  r->add_option("--map", a.map, "map JSON or OA-SLAM text map: its objects in the top view")->check(CLI::ExistingFile);
  r->add_option("--overlays", a.overlays,
                "folder written by `ellreloc relocalize --overlays` for the first --estimate: its worst frames' "
                "pictures are inlined")
      ->check(CLI::ExistingDirectory);
  r->add_option("--worst", a.worst, "how many of the worst frames' overlays to show")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  r->add_option("--out", a.out, "the HTML file to write")->required();
  r->footer(
      "Example: ellreloc report --groundtruth G.txt --estimate ours.txt:ours --estimate oaslam.txt:OA-SLAM "
      "--detections D.json --map map.json --overlays overlays/ --out report.html");
  return r;
}

namespace {

std::string html(const std::string& text) { return escapeXml(text); }

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], kAlphabet[v & 63]};
  }
  if (i + 1 == bytes.size()) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == bytes.size()) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63], '='};
  }
  return out;
}

std::string fixed(double v, int digits) {
  char s[32];
  std::snprintf(s, sizeof s, "%.*f", digits, v);
  return s;
}

const char* kStyle = R"(
body { font-family: "DejaVu Sans", Arial, sans-serif; margin: 24px; color: #222; }
table { border-collapse: collapse; margin: 8px 0 20px; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
th { background: #f0f0f0; cursor: pointer; user-select: none; }
td:first-child, th:first-child { text-align: left; }
td.valid { color: #1a7f37; } td.wrong { color: #c62828; } td.no-pose { color: #888; }
figure { margin: 8px 0 20px; } figure img { max-width: 640px; border: 1px solid #ccc; }
.overlays { display: flex; flex-wrap: wrap; gap: 12px; } figcaption { font-size: 12px; }
svg { max-width: 100%; height: auto; }
)";

// Sorts a table by the clicked column (numbers by value, "no pose" last), toggling the order.
const char* kScript = R"(
function sortTable(table, column, header) {
  const body = table.tBodies[0];
  const ascending = header.dataset.order !== "ascending";
  header.dataset.order = ascending ? "ascending" : "descending";
  const key = row => {
    const cell = row.cells[column];
    const v = cell.dataset.value;
    return v === undefined ? cell.textContent : Number(v);
  };
  const rows = Array.from(body.rows);
  rows.sort((a, b) => {
    const x = key(a), y = key(b);
    const order = typeof x === "number" ? x - y : String(x).localeCompare(String(y));
    return ascending ? order : -order;
  });
  rows.forEach(row => body.appendChild(row));
}
document.querySelectorAll("table.sortable").forEach(table => {
  Array.from(table.tHead.rows[0].cells).forEach((header, column) =>
    header.addEventListener("click", () => sortTable(table, column, header)));
});
document.body.dataset.frames = String(document.querySelectorAll("#frames tbody tr").length);
)";

void summaryTable(std::ostringstream& h, const Evaluation& e) {
  h << "<table id=\"summary\"><thead><tr><th>method</th><th>median position error (cm)</th><th>median rotation "
       "error (deg)</th><th>valid %</th><th>relocalized</th><th>wrong poses</th></tr></thead><tbody>\n";
  for (const MethodEvaluation& m : e.methods) {
    const RelocalizationSummary& s = m.summary;
    h << "<tr><td>" << html(m.label) << "</td><td>" << (s.valid ? fixed(s.median_position_cm, 1) : "-") << "</td><td>"
      << (s.valid ? fixed(s.median_rotation_deg, 2) : "-") << "</td><td>" << fixed(s.validPercent(), 1) << "</td><td>"
      << s.relocalized << " / " << s.frames << "</td><td>" << s.relocalized - s.valid << "</td></tr>\n";
  }
  h << "</tbody></table>\n";
}

void framesTable(std::ostringstream& h, const Evaluation& e) {
  h << "<table id=\"frames\" class=\"sortable\"><thead><tr><th>frame</th>";
  for (const MethodEvaluation& m : e.methods)
    h << "<th>" << html(m.label) << " position (cm)</th><th>" << html(m.label) << " rotation (deg)</th><th>"
      << html(m.label) << " status</th>";
  h << "</tr></thead><tbody>\n";
  for (size_t i = 0; i < e.frames.size(); ++i) {
    h << "<tr><td>" << html(e.frames[i]) << "</td>";
    for (const MethodEvaluation& m : e.methods) {
      const std::optional<PoseError>& err = m.errors[i];
      const std::string status = frameStatus(err);
      const std::string cls = status == "no pose" ? "no-pose" : status;
      if (err)
        h << "<td data-value=\"" << err->position_cm << "\">" << fixed(err->position_cm, 1) << "</td><td data-value=\""
          << err->rotation_deg << "\">" << fixed(err->rotation_deg, 2) << "</td>";
      else  // no pose sorts after every error
        h << "<td data-value=\"1e308\">-</td><td data-value=\"1e308\">-</td>";
      h << "<td class=\"" << cls << "\">" << status << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</tbody></table>\n";
}

/// The first method's worst frames (no pose, then the largest position errors) that have an
/// overlay in the folder, as inline PNGs.
void worstOverlays(std::ostringstream& h, const Evaluation& e, const std::string& folder, int worst) {
  const MethodEvaluation& m = e.methods.front();
  std::vector<size_t> order(e.frames.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto badness = [&](size_t i) {
    return m.errors[i] ? m.errors[i]->position_cm : std::numeric_limits<double>::infinity();
  };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return badness(a) > badness(b); });
  h << "<h2>Worst frames of " << html(m.label) << "</h2>\n<div class=\"overlays\">\n";
  int shown = 0;
  for (size_t i : order) {
    if (shown >= worst) break;
    const std::string path = (std::filesystem::path(folder) / (e.frames[i] + ".png")).string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) continue;
    const std::optional<PoseError>& err = m.errors[i];
    h << "<figure><img alt=\"overlay of frame " << html(e.frames[i]) << "\" src=\"data:image/png;base64,"
      << base64(io::readTextFile(path)) << "\"><figcaption>" << html(e.frames[i]) << ": " << frameStatus(err);
    if (err) h << ", " << fixed(err->position_cm, 1) << " cm, " << fixed(err->rotation_deg, 1) << " deg";
    h << "</figcaption></figure>\n";
    ++shown;
  }
  if (shown == 0) h << "<p>No overlay of these frames in " << html(folder) << ".</p>\n";
  h << "</div>\n";
}

}  // namespace

void report(const ReportArgs& a, const Console& console) {
  EvaluateArgs ev;
  ev.groundtruth = a.groundtruth, ev.estimates = a.estimates, ev.detections = a.detections, ev.map = a.map;
  const Evaluation e = evaluateEstimates(ev);
  checkPaths({{"--out", a.out}}, {{"--groundtruth", a.groundtruth}, {"--detections", a.detections}, {"--map", a.map}});
  const std::optional<ObjectMap> map = a.map.empty() ? std::nullopt : std::optional(io::readMap(a.map));
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>ellreloc report</title>\n<style>"
    << kStyle << "</style>\n</head>\n<body>\n<h1>Relocalization report</h1>\n<p>" << e.frames.size()
    << " query frames; ground truth " << html(a.groundtruth) << (a.map.empty() ? "" : "; map " + html(a.map))
    << ". A pose is valid within " << kValidPositionCm << " cm and " << kValidRotationDeg
    << " degrees of the truth; medians are over valid poses.</p>\n<h2>Table I</h2>\n";
  summaryTable(h, e);
  h << "<h2>Errors</h2>\n<figure>\n" << comparisonFigure(e, map ? &*map : nullptr).svg() << "</figure>\n";
  if (!a.overlays.empty()) worstOverlays(h, e, a.overlays, a.worst);
  h << "<h2>Every frame</h2>\n<p>Click a column to sort by it.</p>\n";
  framesTable(h, e);
  h << "<script>" << kScript << "</script>\n</body>\n</html>\n";
  io::writeFileAtomically(a.out, h.str());
  if (!console.quiet)
    std::printf("wrote %s: %zu frames, %zu methods\n", a.out.c_str(), e.frames.size(), e.methods.size());
}

}  // namespace ellreloc::cli

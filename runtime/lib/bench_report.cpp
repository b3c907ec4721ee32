#include "runtime/lib/bench_report.h"

#include <fmt/format.h>
#include <algorithm>
#include <map>
#include <stdexcept>

#include "systems/io/output_file.h"

namespace rivulet {
namespace {

std::string key(const BenchCase& c) {
    return c.scene + "/" + c.method;
}

// Stage names of all cases, in first-seen order (methods have different jobs).
std::vector<std::string> stage_names(const std::vector<BenchCase>& cases) {
    std::vector<std::string> names;
    for (const BenchCase& c : cases) {
        const auto stages = c.run.find("stages");
        if (stages == c.run.end() || !stages->is_object()) continue;
        for (const auto& [name, ms] : stages->items())
            if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
    return names;
}

double number(const nlohmann::json& j, const char* name) {
    const auto it = j.find(name);
    return it != j.end() && it->is_number() ? it->get<double>() : 0.0;
}

}  // namespace

void derive_scaling(std::vector<BenchCase>& cases) {
    std::map<std::string, const BenchCase*> base;
    for (BenchCase& c : cases) {
        const double frame_ms = number(c.run, "frame_ms");
        if (!(frame_ms > 0))
            throw std::invalid_argument(
                fmt::format("bench case {} at {} threads has no frame time", key(c), c.threads));
        c.frames_per_second = 1000.0 / frame_ms;
        const BenchCase*& b = base[key(c)];
        if (!b || c.threads < b->threads) b = &c;
    }
    for (BenchCase& c : cases) {
        const BenchCase& b = *base[key(c)];
        c.speedup = c.frames_per_second / b.frames_per_second;
        c.efficiency = c.speedup / (double(c.threads) / double(b.threads));
    }
}

nlohmann::json bench_json(const std::vector<BenchCase>& cases, const nlohmann::json& meta) {
    nlohmann::json doc = meta;
    doc["cases"] = nlohmann::json::array();
    for (const BenchCase& c : cases) {
        nlohmann::json j = c.run;
        j["scene"] = c.scene, j["method"] = c.method, j["threads"] = c.threads;
        j["frames_per_second"] = c.frames_per_second;
        j["speedup"] = c.speedup, j["efficiency"] = c.efficiency;
        doc["cases"].push_back(std::move(j));
    }
    return doc;
}

std::string bench_markdown(const std::vector<BenchCase>& cases, const nlohmann::json& meta) {
    std::string md = fmt::format("# rivulet bench\n\n{}\n\n", meta.value("description", std::string()));
    md +=
        "| scene | method | threads | frame ms | frames/s | speedup | efficiency | extract ms | render ms "
        "|\n";
    md += "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const BenchCase& c : cases)
        md +=
            fmt::format("| {} | {} | {} | {:.2f} | {:.1f} | {:.2f} | {:.0f} % | {:.2f} | {:.2f} |\n", c.scene,
                        c.method, c.threads, number(c.run, "frame_ms"), c.frames_per_second, c.speedup,
                        100.0 * c.efficiency, number(c.run, "extract_ms"), number(c.run, "render_ms"));
    const std::vector<std::string> stages = stage_names(cases);
    md += "\nPer-stage medians (ms):\n\n| case |";
    for (const std::string& s : stages) md += " " + s + " |";
    md += "\n|---|";
    for (std::size_t i = 0; i < stages.size(); ++i) md += "---:|";
    md += "\n";
    for (const BenchCase& c : cases) {
        md += fmt::format("| {} T={} |", key(c), c.threads);
        const nlohmann::json st = c.run.value("stages", nlohmann::json::object());
        for (const std::string& s : stages) md += fmt::format(" {:.3f} |", number(st, s.c_str()));
        md += "\n";
    }
    return md;
}

std::string write_gnuplot_inputs(const std::vector<BenchCase>& cases, const std::string& dir) {
    // scaling.dat: one gnuplot data block (two blank lines apart) per scene/method.
    std::vector<std::string> series;
    std::string scaling;
    for (const BenchCase& c : cases) {
        if (std::find(series.begin(), series.end(), key(c)) != series.end()) continue;
        series.push_back(key(c));
        scaling += fmt::format("# {}\n", key(c));
        for (const BenchCase& d : cases)
            if (key(d) == key(c))
                // Ideal: the base rate times the thread ratio, which is fps / efficiency.
                scaling += fmt::format("{} {:.6f} {:.6f}\n", d.threads, d.frames_per_second,
                                       d.frames_per_second / d.efficiency);
        scaling += "\n\n";
    }
    io::write_text_file(dir + "/scaling.dat", scaling);

    const std::vector<std::string> stages = stage_names(cases);
    std::string table = "case";
    for (const std::string& s : stages) table += " \"" + s + "\"";
    table += " render\n";
    for (const BenchCase& c : cases) {
        table += fmt::format("\"{}/T{}\"", key(c), c.threads);
        const nlohmann::json st = c.run.value("stages", nlohmann::json::object());
        for (const std::string& s : stages) table += fmt::format(" {:.6f}", number(st, s.c_str()));
        table += fmt::format(" {:.6f}\n", number(c.run, "render_ms"));
    }
    io::write_text_file(dir + "/stages.dat", table);

    std::string gp = "set terminal pngcairo size 960,600 noenhanced\n";
    // Twenty distinct colours: stacked bars have a segment per job and must not repeat one.
    const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                             "#7f7f7f", "#bcbd22", "#17becf", "#aec7e8", "#ffbb78", "#98df8a", "#ff9896",
                             "#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7", "#dbdb8d", "#9edae5"};
    for (int i = 0; i < 20; ++i) gp += fmt::format("set linetype {} lc rgb '{}'\n", i + 1, colours[i]);
    gp += "set linetype cycle 20\n";
    gp += "set output 'scaling.png'\nset title 'Throughput against threads (dashed: ideal scaling)'\n";
    gp += "set xlabel 'threads'\nset ylabel 'frames/s'\nset key left top\nset grid\n";
    gp += "plot ";
    for (std::size_t i = 0; i < series.size(); ++i) {
        gp += fmt::format("'scaling.dat' index {} using 1:2 with linespoints lw 2 lc {} title '{}', ", i,
                          i + 1, series[i]);
        gp += fmt::format("'scaling.dat' index {} using 1:3 with lines dt 2 lc {} title '{} ideal'", i, i + 1,
                          series[i]);
        gp += i + 1 < series.size() ? ", \\\n     " : "\n";
    }
    gp += "set output 'stages.png'\nset title 'Per-stage medians (ms), stacked'\nunset xlabel\n";
    gp += "set ylabel 'ms'\nset style data histograms\nset style histogram rowstacked\n";
    gp += "set style fill solid 0.85 border -1\nset boxwidth 0.7\nset xtics rotate by -30\n";
    gp += "set key outside right top\nset grid y\n";
    gp += fmt::format("plot for [i=2:{}] 'stages.dat' using i:xtic(1) title columnheader(i)\n",
                      stages.size() + 2);
    const std::string path = dir + "/plots.gp";
    io::write_text_file(path, gp);
    return path;
}

}  // namespace rivulet

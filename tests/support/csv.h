// Test helper: reads a numeric CSV with a header line into rows of doubles.
// Lines starting with '#' before the header are kept as comments.
#pragma once

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace bouncecheck::test {

struct Csv {
    std::vector<std::string> comments;
    std::vector<std::string> header;
    std::vector<std::vector<double>> rows;
};

inline std::vector<std::string> split_commas(const std::string& line) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
    return out;
}

inline Csv read_csv(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    Csv csv;
    std::string line;
    while (std::getline(in, line) && line.starts_with('#')) csv.comments.push_back(line);
    csv.header = split_commas(line);
    while (std::getline(in, line)) {
        std::vector<double> row;
        for (const auto& cell : split_commas(line)) row.push_back(std::strtod(cell.c_str(), nullptr));
        csv.rows.push_back(std::move(row));
    }
    return csv;
}

}  // namespace bouncecheck::test

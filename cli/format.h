#pragma once

// Printing of vectors and matrices for the CLI: fixed-width text and nested JSON arrays.

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include <shapedb/core/types.h>

namespace shapedb::cli {

/// A vector or matrix as JSON: a list, or a list of rows.
template <typename Derived>
nlohmann::json toJson(const Eigen::MatrixBase<Derived>& m) {
  if (m.cols() == 1) {
    nlohmann::json out = nlohmann::json::array();
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      out.push_back(m(i, 0));
    return out;
  }
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      row.push_back(m(i, j));
    rows.push_back(std::move(row));
  }
  return rows;
}

/// A vector as "(x, y, z)"; a matrix as one indented line per row.
template <typename Derived>
std::string toText(const Eigen::MatrixBase<Derived>& m, const std::string& indent = "") {
  char buffer[64];
  std::string out;
  if (m.cols() == 1) {
    out = "(";
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      std::snprintf(buffer, sizeof buffer, "%s%.9g", i ? ", " : "", m(i, 0));
      out += buffer;
    }
    return out + ")";
  }
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    out += indent + "[";
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      std::snprintf(buffer, sizeof buffer, " %15.9g", m(i, j));
      out += buffer;
    }
    out += " ]\n";
  }
  return out;
}

}  // namespace shapedb::cli

#include "fieldvision/util/csv.h"

#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::util {

CsvTable CsvTable::Read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  FV_REQUIRE(in.good(), "cannot open CSV file '{}'", path);
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path);
}

CsvTable CsvTable::Parse(const std::string& text, const std::string& name) {
  CsvTable t;
  t.name_ = name;
  std::istringstream in(text);
  SkipUtf8Bom(in);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (Trim(line).empty() || StartsWith(Trim(line), "#")) continue;
    std::vector<std::string> fields = Split(line, ',');
    for (auto& f : fields) f = Trim(f);
    if (t.header_.empty()) {
      t.header_ = fields;
      for (size_t i = 0; i < fields.size(); ++i) {
        FV_REQUIRE(!fields[i].empty(), "{}:{}: empty column name in header", name, line_no);
        FV_REQUIRE(t.index_.emplace(fields[i], static_cast<int>(i)).second,
                   "{}:{}: duplicate column '{}'", name, line_no, fields[i]);
      }
      continue;
    }
    FV_REQUIRE(fields.size() == t.header_.size(), "{}:{}: {} fields, the header has {}", name,
               line_no, fields.size(), t.header_.size());
    t.rows_.push_back(std::move(fields));
    t.line_numbers_.push_back(line_no);
  }
  FV_REQUIRE(!t.header_.empty(), "CSV file '{}' is empty (no header)", name);
  return t;
}

void CsvTable::Require(const std::vector<std::string>& columns) const {
  std::string missing;
  for (const auto& c : columns) {
    if (!Has(c)) missing += (missing.empty() ? "" : ", ") + c;
  }
  FV_REQUIRE(missing.empty(), "CSV file '{}' lacks column(s): {}", name_, missing);
}

int CsvTable::Column(const std::string& column) const {
  auto it = index_.find(column);
  FV_REQUIRE(it != index_.end(), "CSV file '{}' lacks column '{}'", name_, column);
  return it->second;
}

const std::string& CsvTable::Get(size_t row, const std::string& column) const {
  FV_REQUIRE(row < rows_.size(), "CSV file '{}': row {} out of range", name_, row);
  return rows_[row][Column(column)];
}

std::string CsvTable::Where(size_t row) const {
  return fmt::format("{}:{}", name_, row < line_numbers_.size() ? line_numbers_[row] : 0);
}

double CsvTable::GetDouble(size_t row, const std::string& column) const {
  return ParseDouble(Get(row, column), fmt::format("{} column '{}'", Where(row), column));
}

long long CsvTable::GetInt(size_t row, const std::string& column) const {
  return ParseInt(Get(row, column), fmt::format("{} column '{}'", Where(row), column));
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& header, int precision)
    : path_(path), out_(path), columns_(header.size()), precision_(precision) {
  FV_REQUIRE(out_.good(), "cannot write CSV file '{}'", path);
  for (size_t i = 0; i < header.size(); ++i) out_ << (i ? "," : "") << header[i];
  out_ << '\n';
}

void CsvWriter::Sep() {
  FV_REQUIRE(in_row_ < columns_, "CSV file '{}': too many fields in a row", path_);
  if (in_row_++ > 0) out_ << ',';
}

CsvWriter& CsvWriter::operator<<(const std::string& v) {
  Sep();
  out_ << v;
  return *this;
}

CsvWriter& CsvWriter::operator<<(double v) {
  Sep();
  if (std::isfinite(v)) {
    out_ << fmt::format("{:.{}f}", v, precision_);
  } else {
    out_ << "nan";
  }
  return *this;
}

CsvWriter& CsvWriter::operator<<(int v) {
  Sep();
  out_ << v;
  return *this;
}

CsvWriter& CsvWriter::operator<<(long long v) {
  Sep();
  out_ << v;
  return *this;
}

void CsvWriter::EndRow() {
  FV_REQUIRE(in_row_ == columns_, "CSV file '{}': row has {} fields, expected {}", path_, in_row_,
             columns_);
  out_ << '\n';
  in_row_ = 0;
}

void CsvWriter::Close() {
  out_.flush();
  FV_REQUIRE(out_.good(), "error while writing CSV file '{}'", path_);
  out_.close();
}

}  // namespace fv::util

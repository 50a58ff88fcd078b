#include "fieldvision/util/csv.h"

#include <cctype>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/input_file.h"
#include "fieldvision/util/strings.h"

namespace fv::util {

namespace {

// RFC 4180: a field with a comma or a double quote is quoted and its quotes doubled; line
// breaks become spaces (a row is one line).
std::string CsvField(std::string v) {
  for (char& c : v) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  // Also quoted: a field the reader would take otherwise (a first field starting with '#' reads
  // as a comment line, spaces at either end are trimmed).
  const bool edge =
      !v.empty() && (v.front() == '#' || std::isspace(static_cast<unsigned char>(v.front())) ||
                     std::isspace(static_cast<unsigned char>(v.back())));
  if (!edge && v.find_first_of(",\"") == std::string::npos) return v;
  std::string q = "\"";
  for (const char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// The fields of one line, quoted ones (RFC 4180) unquoted; unquoted ones trimmed. Throws naming
// `where` for a quote left open or text after a closing quote.
std::vector<std::string> SplitCsvLine(const std::string& line, const std::string& where) {
  std::vector<std::string> fields;
  size_t i = 0;
  for (;;) {
    std::string field;
    const size_t start = line.find_first_not_of(" \t", i);
    if (start != std::string::npos && line[start] == '"') {
      size_t j = start + 1;
      for (;; ++j) {
        FV_REQUIRE(j < line.size(), "{}: a quoted field is not closed", where);
        if (line[j] != '"') {
          field += line[j];
        } else if (j + 1 < line.size() && line[j + 1] == '"') {
          field += '"';
          ++j;
        } else {
          break;
        }
      }
      const size_t after = line.find_first_not_of(" \t", j + 1);
      FV_REQUIRE(after == std::string::npos || line[after] == ',',
                 "{}: text after a quoted field's closing quote", where);
      fields.push_back(field);
      if (after == std::string::npos) return fields;
      i = after + 1;
      continue;
    }
    const size_t comma = line.find(',', i);
    fields.push_back(
        Trim(line.substr(i, comma == std::string::npos ? std::string::npos : comma - i)));
    if (comma == std::string::npos) return fields;
    i = comma + 1;
  }
}

}  // namespace

std::string ReadCsvText(const std::string& path, const std::string& what) {
  RequireInputFile(path, what);
  std::ifstream in(path, std::ios::binary);
  FV_REQUIRE(in.good(), "cannot open {} '{}'", what, path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CsvTable CsvTable::Read(const std::string& path) { return Parse(ReadCsvText(path), path); }

CsvTable CsvTable::Parse(const std::string& text, const std::string& name) {
  return ParseRows(text, name, nullptr);
}

CsvTable CsvTable::ParseHeaderless(const std::string& text, const std::string& name,
                                   const std::vector<std::string>& names) {
  return ParseRows(text, name, &names);
}

// The rows of `text`: its first line is the header, or with `names` (no header) the first row
// takes as many of them as it has fields.
CsvTable CsvTable::ParseRows(const std::string& text, const std::string& name,
                             const std::vector<std::string>* names) {
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
    std::vector<std::string> fields = SplitCsvLine(line, fmt::format("{}:{}", name, line_no));
    if (t.header_.empty()) {
      if (names == nullptr) {
        t.header_ = fields;
      } else {
        FV_REQUIRE(fields.size() <= names->size(), "{}:{}: {} fields, at most {} expected", name,
                   line_no, fields.size(), names->size());
        t.header_.assign(names->begin(), names->begin() + static_cast<long>(fields.size()));
      }
      for (size_t i = 0; i < t.header_.size(); ++i) {
        FV_REQUIRE(!t.header_[i].empty(), "{}:{}: empty column name in header", name, line_no);
        FV_REQUIRE(t.index_.emplace(t.header_[i], static_cast<int>(i)).second,
                   "{}:{}: duplicate column '{}'", name, line_no, t.header_[i]);
      }
      if (names == nullptr) continue;
    }
    FV_REQUIRE(fields.size() == t.header_.size(), "{}:{}: {} fields, {} {}", name, line_no,
               fields.size(), names == nullptr ? "the header has" : "the first row has",
               t.header_.size());
    t.rows_.push_back(std::move(fields));
    t.line_numbers_.push_back(line_no);
  }
  FV_REQUIRE(!t.header_.empty() || names != nullptr, "CSV file '{}' is empty (no header)", name);
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
  for (size_t i = 0; i < header.size(); ++i) out_ << (i ? "," : "") << CsvField(header[i]);
  out_ << '\n';
}

void CsvWriter::Sep() {
  FV_REQUIRE(in_row_ < columns_, "CSV file '{}': too many fields in a row", path_);
  if (in_row_++ > 0) out_ << ',';
}

CsvWriter& CsvWriter::operator<<(const std::string& v) {
  Sep();
  out_ << CsvField(v);
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

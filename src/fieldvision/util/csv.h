// CSV files with a header row: a strict reader that names file, line and column in its errors,
// and a writer that formats doubles with a fixed precision. Fields with commas or quotes are
// quoted as RFC 4180 says (a zone or player name "box, left"); a row is one line.
#pragma once

#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace fv::util {

// The whole text of `path` for CsvTable::Parse or ParseHeaderless; throws fv::Error "cannot open
// {what} '{path}'".
std::string ReadCsvText(const std::string& path, const std::string& what = "CSV file");

class CsvTable {
 public:
  // Reads `path`; throws fv::Error if it cannot be opened, is empty or has ragged rows.
  static CsvTable Read(const std::string& path);
  static CsvTable Parse(const std::string& text, const std::string& name);
  // A file without a header row (MOTChallenge's det.txt, gt.txt): every line is a data row, the
  // first one's fields named by the first of `names` (it may have no more), the others as many.
  // Without rows the table has no columns either.
  static CsvTable ParseHeaderless(const std::string& text, const std::string& name,
                                  const std::vector<std::string>& names);

  const std::string& name() const { return name_; }
  const std::vector<std::string>& header() const { return header_; }
  size_t rows() const { return rows_.size(); }
  bool Has(const std::string& column) const { return index_.count(column) > 0; }
  // Throws naming the missing columns.
  void Require(const std::vector<std::string>& columns) const;
  int Column(const std::string& column) const;
  const std::string& Get(size_t row, const std::string& column) const;
  double GetDouble(size_t row, const std::string& column) const;
  long long GetInt(size_t row, const std::string& column) const;
  // "file:line" of a data row, for messages.
  std::string Where(size_t row) const;

 private:
  static CsvTable ParseRows(const std::string& text, const std::string& name,
                            const std::vector<std::string>* names);
  std::string name_;
  std::vector<std::string> header_;
  std::map<std::string, int> index_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<int> line_numbers_;
};

class CsvWriter {
 public:
  // Opens `path` for writing (throws naming it on failure) and writes the header.
  CsvWriter(const std::string& path, const std::vector<std::string>& header, int precision = 6);
  CsvWriter& operator<<(const std::string& v);
  CsvWriter& operator<<(const char* v) { return *this << std::string(v); }
  CsvWriter& operator<<(double v);
  CsvWriter& operator<<(int v);
  CsvWriter& operator<<(long long v);
  CsvWriter& operator<<(size_t v) { return *this << static_cast<long long>(v); }
  // Ends the row; throws if the row has the wrong number of fields.
  void EndRow();
  void Close();

 private:
  void Sep();
  std::string path_;
  std::ofstream out_;
  size_t columns_;
  size_t in_row_ = 0;
  int precision_;
};

}  // namespace fv::util

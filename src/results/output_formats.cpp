// The registered output formats (results/output_sink.hpp): a new format is one row here and
// its make function in a file of its own.
#include <string>

#include "railcrash/core/error.hpp"
#include "railcrash/results/hdf5_file.hpp"
#include "railcrash/results/output_sink.hpp"

namespace railcrash {

std::unique_ptr<OutputSink> make_csv_sink();     // src/results/csv_sink.cpp
std::unique_ptr<OutputSink> make_hdf5_sink();    // src/results/hdf5_sink.cpp
std::unique_ptr<OutputSink> make_memory_sink();  // src/results/memory_sink.cpp

const std::vector<OutputFormat>& output_formats() {
  static const std::vector<OutputFormat> formats = {
      {"csv", true, "csv", "timeseries.csv, events.csv, accelerations.csv, energy.csv, energy_zones.csv",
       {"timeseries.csv", "events.csv", "accelerations.csv", "energy.csv", "energy_zones.csv"}, nullptr, make_csv_sink},
      {"hdf5", true, "hdf5: DIR/timeseries.h5 in place of the per-row CSV files (README \"Binary output\")",
       "timeseries.h5: timeseries, events, accelerations, energy", {"timeseries.h5"}, require_hdf5, make_hdf5_sink},
      {"memory", false, "", "", {}, nullptr, make_memory_sink},
  };
  return formats;
}

const OutputFormat& output_format(const std::string& name) {
  std::string names;
  for (const OutputFormat& format : output_formats()) {
    if (format.name == name) return format;
    names += (names.empty() ? "" : ", ") + std::string(format.name);
  }
  throw InputError("no output format '" + name + "'; the formats are " + names);
}

std::vector<std::string> file_output_format_names() {
  std::vector<std::string> names;
  for (const OutputFormat& format : output_formats())
    if (format.writes_files) names.push_back(format.name);
  return names;
}

std::string output_format_help() {
  std::vector<std::string> helps;
  for (const OutputFormat& format : output_formats())
    if (format.writes_files) helps.push_back(format.help);
  std::string text;
  for (std::size_t k = 0; k < helps.size(); ++k) text += (k == 0 ? "" : k + 1 == helps.size() ? ", or " : ", ") + helps[k];
  return text;
}

void require_output_format(const std::string& name) {
  const OutputFormat& format = output_format(name);
  if (format.require) format.require();
}

std::unique_ptr<OutputSink> make_output_sink(const std::string& name) {
  require_output_format(name);
  return output_format(name).make();
}

}  // namespace railcrash

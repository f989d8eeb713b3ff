// The timeseries kept in memory (results/output_sink.hpp "memory"): the library's and the
// Python module's runs (api.hpp), which need no folder. The events are the run outcome's.
#include <memory>

#include "railcrash/results/output_sink.hpp"

namespace railcrash {

namespace {

class MemorySink : public OutputSink {
 public:
  void begin(const OutputLayout& layout) override { columns_.resize(layout.table(OutputTable::Timeseries).columns.size()); }
  bool takes(OutputTable table) const override { return table == OutputTable::Timeseries; }
  void row(OutputTable, const double* values) override {
    for (std::size_t column = 0; column < columns_.size(); ++column) columns_[column].push_back(values[column]);
  }
  std::string event(const EventRecord&) override { return ""; }
  std::string check(bool) override { return ""; }
  std::string finish(const CrushZoneTracker&) override { return ""; }
  std::vector<std::vector<double>>* kept_columns() override { return &columns_; }

 private:
  std::vector<std::vector<double>> columns_;  // per timeseries column, one value per row
};

}  // namespace

std::unique_ptr<OutputSink> make_memory_sink() { return std::make_unique<MemorySink>(); }

}  // namespace railcrash

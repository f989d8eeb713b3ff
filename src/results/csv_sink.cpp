// The CSV files of a run folder (results/output_sink.hpp "csv"): timeseries.csv, events.csv,
// accelerations.csv and energy.csv as the run goes, energy_zones.csv at its end; each file's
// first line is the run's provenance (results/provenance.hpp), then its header.
#include <cerrno>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>
#include <utility>

#include "railcrash/core/error.hpp"
#include "railcrash/results/buffered_file.hpp"
#include "railcrash/results/crush_zones.hpp"
#include "railcrash/results/output_sink.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

namespace {

class CsvSink : public OutputSink {
 public:
  void begin(const OutputLayout& layout) override {
    directory_ = layout.directory;
    provenance_ = layout.provenance;
    files_[0] = {open("timeseries.csv"), "timeseries.csv"};  // (in this order: an error names the first file that fails)
    events_ = open("events.csv");
    files_[1] = {open("accelerations.csv"), "accelerations.csv"};
    files_[2] = {open("energy.csv"), "energy.csv"};
    for (std::size_t k = 0; k < kOutputTableCount; ++k) {
      const std::vector<std::string>& columns = layout.tables[k].columns;
      for (std::size_t c = 0; c < columns.size(); ++c) files_[k].file->text((c ? "," : "") + columns[c]);
      files_[k].file->character('\n');
      widths_[k] = columns.size();
    }
    events_->text("t,element,event,value\n");
  }

  bool takes(OutputTable) const override { return true; }

  void row(OutputTable table, const double* values) override {
    const std::size_t k = static_cast<std::size_t>(table);
    BufferedFile& file = *files_[k].file;
    file.number(values[0]);
    write_row_tail(file, values + 1, widths_[k] - 1);
    file.character('\n');
    if (table == OutputTable::Timeseries) row_ends_.emplace_back(file.appended(), values[0]);
  }

  std::string event(const EventRecord& record) override {
    std::string element = record.element, what = record.what;
    for (std::string* text : {&element, &what})
      if (text->find_first_of(",\"") != std::string::npos) {
        std::string quoted = "\"";
        for (char c : *text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
        *text = quoted + "\"";
      }
    events_->number(record.t);
    events_->text("," + element + "," + what + ",");
    events_->number(record.value);
    events_->character('\n');
    if (events_->error() != 0) return failed("events.csv", events_->error());
    return "";
  }

  std::string check(bool flush) override {
    // In the order they were opened: the first failure named is the first file's.
    const std::pair<BufferedFile*, const char*> files[] = {{files_[0].file.get(), files_[0].name},
                                                           {events_.get(), "events.csv"},
                                                           {files_[1].file.get(), files_[1].name},
                                                           {files_[2].file.get(), files_[2].name}};
    std::string failure;
    for (const auto& [file, name] : files) {
      if (flush) file->flush();
      if (file->error() != 0 && failure.empty()) failure = failed(name, file->error());
    }
    // The rows whose last byte the OS has.
    const BufferedFile& timeseries = *files_[0].file;
    for (; !row_ends_.empty() && row_ends_.front().first <= timeseries.written(); row_ends_.pop_front()) {
      ++rows_on_disk_;
      t_on_disk_ = row_ends_.front().second;
    }
    if (failure.empty()) return "";
    // Say what the files hold, not what was computed.
    return failure + (rows_on_disk_ == 0 ? "; timeseries.csv holds no output row"
                                         : "; timeseries.csv holds the first " + std::to_string(rows_on_disk_) +
                                               " rows whole, up to t = " + json_number(t_on_disk_) +
                                               " (the rows after it were lost)");
  }

  std::string finish(const CrushZoneTracker& zones) override {
    const std::string path = directory_ + "/energy_zones.csv";
    std::ofstream out(path, std::ios::binary);
    out << provenance_comment(*provenance_) << zones.csv();
    out.flush();
    if (!out) return "cannot write " + path + ": " + std::strerror(errno);
    return "";
  }

 private:
  struct File {
    std::unique_ptr<BufferedFile> file;
    const char* name = "";
  };
  std::string directory_;
  const Provenance* provenance_ = nullptr;
  std::array<File, kOutputTableCount> files_;  // per OutputTable
  std::array<std::size_t, kOutputTableCount> widths_{};  // columns per row
  std::unique_ptr<BufferedFile> events_;
  // The rows the OS has whole: timeseries.csv's rows up to its bytes written.
  std::size_t rows_on_disk_ = 0;
  double t_on_disk_ = -1.0;                                 // [time] the last of them
  std::deque<std::pair<std::uint64_t, double>> row_ends_;  // byte after each row not yet written, its t

  /// DIR/name created with the provenance line; InputError with the OS's reason when it cannot be.
  std::unique_ptr<BufferedFile> open(const char* name) {
    auto file = std::make_unique<BufferedFile>(directory_ + "/" + name);
    if (!file->is_open())
      throw InputError("cannot write into the output folder '" + directory_ + "': " + name + ": " + std::strerror(file->error()));
    file->text(provenance_comment(*provenance_));  // every CSV file's first line
    return file;
  }
  std::string failed(const char* name, int error_number) const {
    return "cannot write " + directory_ + "/" + name + ": " + std::strerror(error_number);
  }
};

}  // namespace

std::unique_ptr<OutputSink> make_csv_sink() { return std::make_unique<CsvSink>(); }

}  // namespace railcrash

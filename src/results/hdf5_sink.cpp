// DIR/timeseries.h5 of a run folder (results/output_sink.hpp "hdf5"): the timeseries,
// accelerations, energy and events tables as datasets of one file (results/hdf5_file.hpp).
#include <memory>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model.hpp"
#include "railcrash/results/hdf5_file.hpp"
#include "railcrash/results/output_sink.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/results.hpp"
#include "railcrash/solver/dae_system.hpp"

namespace railcrash {

namespace {

class Hdf5Sink : public OutputSink {
 public:
  void begin(const OutputLayout& layout) override {
    file_ = std::make_unique<Hdf5File>(layout.directory + "/timeseries.h5");  // (throws)
    const Model& model = *layout.model;
    const Provenance& provenance = *layout.provenance;
    const bool si = model.units == UnitSystem::SI;
    file_->attribute("railcrash_version", provenance.version);
    file_->attribute("run_id", provenance.run_id);
    file_->attribute("provenance", provenance_json(provenance));
    file_->attribute("model", model.name);
    file_->attribute("model_file", model.file);
    file_->attribute("units", std::string(unit_system_name(model.units)) + ": length " + (si ? "m" : "in") +
                                  ", time s, angle rad, force " + (si ? "N" : "lbf") + ", energy " + (si ? "J" : "in*lbf"));
    for (std::size_t k = 0; k < kOutputTableCount; ++k)
      tables_[k] = file_->add_table(layout.tables[k].name, layout.tables[k].columns, layout.tables[k].units);
    events_ = file_->add_event_table("events");
    if (!file_->flush()) throw InputError(file_->error());
  }

  bool takes(OutputTable) const override { return true; }

  void row(OutputTable table, const double* values) override {
    file_->append(tables_[static_cast<std::size_t>(table)], values);
    if (table != OutputTable::Timeseries) return;
    ++rows_;
    t_last_ = values[0];
  }

  std::string event(const EventRecord& record) override {
    file_->append_event(events_, record.t, record.element, record.what, record.value);
    return "";  // (a failed write shows at the next check)
  }

  std::string check(bool flush) override {
    if (flush) file_->flush();
    if (file_->error().empty()) {
      if (flush) {  // every row so far is in the file
        rows_on_disk_ = rows_;
        t_on_disk_ = rows_ == 0 ? -1.0 : t_last_;
      }
      return "";
    }
    // Say what the file holds, not what was computed.
    return file_->error() + (rows_on_disk_ == 0 ? "; timeseries.h5 holds no output row"
                                                : "; timeseries.h5 holds the first " + std::to_string(rows_on_disk_) +
                                                      " rows whole, up to t = " + json_number(t_on_disk_) +
                                                      " (the rows after it were lost)");
  }

  std::string finish(const CrushZoneTracker&) override { return ""; }

  std::string summary_entry() const override {
    return "  \"output\": {\"format\": \"hdf5\", \"files\": [\"timeseries.h5\"], \"datasets\": [\"timeseries\", "
           "\"accelerations\", \"energy\", \"events\"]"
           // The rows the file held whole at its last flush that succeeded (a kill after it leaves
           // them readable; rows after them may be missing or zero).
           ", \"valid_rows\": " +
           std::to_string(rows_on_disk_) + ", \"valid_to_t\": " + json_number(t_on_disk_ < 0.0 ? 0.0 : t_on_disk_) + "},\n";
  }

 private:
  std::unique_ptr<Hdf5File> file_;
  std::array<int, kOutputTableCount> tables_{};  // the file's table per OutputTable
  int events_ = -1;
  std::size_t rows_ = 0;  // timeseries rows appended
  double t_last_ = 0.0;   // [time] the last of them
  // The rows at the file's last flush that succeeded.
  std::size_t rows_on_disk_ = 0;
  double t_on_disk_ = -1.0;  // [time] the last of them (-1: none)
};

}  // namespace

std::unique_ptr<OutputSink> make_hdf5_sink() { return std::make_unique<Hdf5Sink>(); }

}  // namespace railcrash

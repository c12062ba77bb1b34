// `navbus import`: a user's logs, described by a data set YAML, into a navbus recording
// (components/importers). Offline: no DDS participant.
#include <cstdio>

#include "navbus/importers/importer.hpp"
#include "subcommand.hpp"

namespace navbus::tool::cli {
namespace {

class ImportCommand final : public Subcommand {
 public:
  void add(CLI::App& app) override {
    cli_ = app.add_subcommand(
        "import",
        "real logs into a navbus recording (for replay and offline): an IMU CSV file with its "
        "clock (RTKLIB time tag), RTKLIB solutions (.pos), as a data set YAML describes them "
        "(config/datasets/)");
    cli_->add_option("dataset", dataset_, "data set YAML")->required()->check(CLI::ExistingFile);
    cli_->add_option("-o,--out", out_dir_, "recording directory (created)")->required();
  }
  bool usesBus() const override { return false; }
  int run(bus::Participant::Options& /*options*/, bus::ShutdownSignal& /*shutdown*/) override {
    const auto description = importers::readDatasetDescription(dataset_);
    const auto report = importers::importDataset(description, out_dir_);
    std::fputs(report.text.c_str(), stdout);
    return 0;
  }

 private:
  std::string dataset_;
  std::string out_dir_;
};

}  // namespace

void addImportSubcommands(Subcommands& out) {
  out.push_back(std::make_unique<ImportCommand>());
}

}  // namespace navbus::tool::cli

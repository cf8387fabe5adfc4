// output_file.cc — carmen_compat's atomic output file (atomic_file.h) as
// Python's _OutputFile, for what Python writes itself (bag2carmen's log,
// carmen2bag's bag): the same temporary, checks and rename as every map the
// engine writes, so no Python file keeps a transaction of its own; and its
// TemporaryOnSignal as _TemporaryOnSignal, for the scratch files a writer
// that takes only a path (rosbags') makes before its output is copied in.
#include <nanobind/nanobind.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/string.h>

#include <filesystem>
#include <memory>
#include <string>

#include "bindings.h"
#include "carmen_compat/atomic_file.h"
#include "carmen_compat/error.h"

namespace vasco_py {

namespace {

using namespace nb::literals;

// One output: its AtomicOutput until committed or abandoned.
struct OutputFile {
  std::unique_ptr<carmen::AtomicOutput> out;
  int fd = -1;  // taken by Python (os.fdopen owns it then)

  carmen::AtomicOutput &open() {
    if (!out) throw carmen::Error(carmen::ErrorCode::State, "_OutputFile: already committed or abandoned");
    return *out;
  }
};

// A path registered with the signal clean-up until released.
struct ScratchPath {
  std::unique_ptr<carmen::TemporaryOnSignal> registered;
};

}  // namespace

void bind_output_file(nb::module_ &m) {
  m.def("_remove_temporaries_on_signals", &carmen::remove_temporaries_on_signals,
        "Installs the engine's SIGINT, SIGTERM and SIGHUP handlers (atomic_file.h): they remove every live\n"
        "temporary of this process, then end it as the signal would. For console scripts that write through\n"
        "_OutputFile (bag2carmen); a library user's signal handlers are theirs.");
  nb::class_<OutputFile>(m, "_OutputFile",
                         "A file written whole or not at all: a hidden temporary beside the target (mode 0666 less\n"
                         "the umask), renamed over it by commit(); abandon() (or the object's end) removes it.\n"
                         "A target that is not a regular file (a FIFO, a directory) is refused (FileError).")
      .def(
          "__init__",
          [](OutputFile *self, const std::filesystem::path &path) {
            new (self) OutputFile();
            self->out = std::make_unique<carmen::AtomicOutput>(path.string());
          },
          "path"_a)
      .def(
          "take_fd", [](OutputFile &f) { return f.fd = f.open().take_fd(); },
          "The temporary's descriptor, open for writing (once); the caller closes it before commit().")
      .def(
          "commit",
          [](OutputFile &f) {
            nb::gil_scoped_release release;
            f.open().commit();
            f.out.reset();
          },
          "Renames the complete, closed temporary over the target (FileError naming the target).")
      .def(
          "abandon", [](OutputFile &f) { f.out.reset(); },
          "Removes the temporary now, unless committed (then it does nothing).");
  nb::class_<ScratchPath>(m, "_TemporaryOnSignal",
                          "A path of the caller's making (a file, or a directory: removed once empty) that the\n"
                          "signal handlers of _remove_temporaries_on_signals remove, until release(). Register it\n"
                          "before it is made; removing it otherwise is the caller's job.")
      .def(
          "__init__",
          [](ScratchPath *self, const std::filesystem::path &path) {
            new (self) ScratchPath{std::make_unique<carmen::TemporaryOnSignal>(path.string())};
          },
          "path"_a)
      .def(
          "release", [](ScratchPath &p) { p.registered.reset(); },
          "No longer removed on a signal (once the caller has removed it).");
}

}  // namespace vasco_py

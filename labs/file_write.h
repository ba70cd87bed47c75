// Checked file writes: every byte written, flushed to disk and closed, each step's return checked;
// the file appears under its name only when all of that succeeded (temporary name, then rename),
// and a failure removes the temporary file and throws std::system_error (code: the errno), one line
// naming the file with the system's error text ("cannot write out/results.json: No space left on device").
#pragma once
#include <string>
#include <string_view>

namespace dyn {

// Writes contents to path via path + ".tmp": open, write loop, fsync, close, rename; durable also
// fsyncs the folder, so the new name survives a crash (for files that are the record of a grade).
void writeFileChecked(const std::string& path, std::string_view contents, bool durable = false);

// fsync of a folder (after renames into it); throws like writeFileChecked.
void syncDirectory(const std::string& dir);

// For a process whose writes become a record only through a later syncFileSystem (a batch's grader:
// the batch syncs OUT once before it writes its gradebook, and a batch that did not finish is graded
// afresh): writeFileChecked and syncDirectory skip their fsyncs. Temporary name and rename stay, so
// no reader sees a half-written file while the system runs.
void deferDurability(bool defer);

// syncfs of the file system holding path: everything written to it is on disk; throws like writeFileChecked.
void syncFileSystem(const std::string& path);

// Test hook: DYNLAB_FAULT_INJECTION="enospc:NAME" makes writing a file whose name is NAME, or ends
// with NAME (enospc:.png: every PNG), fail as a full disk would, after writing half of it.
// True when such a fault is asked for file_name. Unset in normal use.
bool writeFaultInjected(const std::string& file_name);

}  // namespace dyn

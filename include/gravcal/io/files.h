// gravcal/io/files.h: whole files in and out, with errors that name the file,
// and the destination contract every command and the Python package keep.
//
// The destination contract (docs/data_contract.md, "Destinations"):
//  - every destination is checked before any work starts (CheckDestinations);
//  - a destination that is the same file as an input of the command, or as
//    another of its outputs, is refused (device and inode, links resolved);
//  - a destination that exists and is not a regular file (FIFO, device,
//    folder, socket) is refused: gravcal never renames over one;
//  - a symbolic link is followed: its target is replaced atomically;
//  - "-" is standard output only where the command streams, refused elsewhere
//    (and WriteFileAtomically never makes a file called "-": write "./-");
//  - a write goes to a temporary in the destination's folder named
//    ".gravcal-tmp.<pid>.<random>.<name>", renamed into place; only names of
//    that form whose process is gone and whose lock is free are ever removed
//    (RemoveStaleTemporaries);
//  - messages name the destination, never the temporary.
#ifndef GRAVCAL_IO_FILES_H_
#define GRAVCAL_IO_FILES_H_

#include <string>
#include <vector>

namespace gravcal {

// Reads a whole file into `bytes`; errors name the file ("x.csv: cannot
// open: No such file or directory").
bool ReadFileBytes(const std::string& path, std::string* bytes, std::string* error);

// Writes `contents` to `path` through a temporary file in the destination's
// folder and a rename, so a failure never leaves a partial file. A symbolic
// link at `path` is followed (its target is replaced); a `path` that exists
// and is not a regular file, and the name "-", are refused.
bool WriteFileAtomically(const std::string& path, const std::string& contents, std::string* error);

// One file of WriteFilesAtomically.
struct FileContents {
  std::string path;  // "" = not written
  std::string contents;
};

// Writes several files as one output: every temporary is written and closed
// before the first is renamed into place, so a failure while writing (a full
// disk, a folder that cannot take a file) leaves every destination as it was;
// no file the user had is removed. Only a rename failing after others were
// done (the folder vanished meanwhile) can leave some files new.
bool WriteFilesAtomically(const std::vector<FileContents>& files, std::string* error);

// Creates the folder `path` and every missing folder above it (mkdir -p).
// False with "<path>: cannot create the folder '<level>': <why>".
bool MakeFolders(const std::string& path, std::string* error);

// A file written in pieces, then put in place at once (the writer behind
// WriteFileAtomically, for outputs streamed in constant memory).
class AtomicFile {
 public:
  AtomicFile() = default;
  // Abort()s when not committed.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Creates the temporary beside the destination `path` (beside a symbolic
  // link's target). False with "<path>: <why>" when the destination cannot
  // take a file.
  bool Open(const std::string& path, std::string* error);
  bool Write(const char* data, size_t size, std::string* error);
  // Finishes the temporary (closes it) and checks that the destination is
  // still no non-regular file; the destination is not touched yet.
  bool Close(std::string* error);
  // Renames the temporary over the destination (Close()s first if needed).
  bool Commit(std::string* error);
  // Removes the temporary; the destination is left as it was.
  void Abort();

 private:
  int fd_ = -1;
  std::string path_;       // as given, for messages
  std::string target_;     // the destination, links resolved
  std::string temporary_;  // beside target_
};

// One file (or folder) a command writes.
struct Destination {
  std::string path;  // "" = not written this time (skipped)
  std::string flag;  // how the user named it, for messages ("--output")
  // "-" is standard output for this destination (the command streams it).
  bool standard_output = false;
  // A folder the command fills (created when missing).
  bool folder = false;
};

// One file (or folder) a command reads.
struct Source {
  std::string path;  // "" or "-" (standard input): not compared
  std::string flag;
};

// Checks, before any work, that each destination can be written and destroys
// nothing: not an existing non-regular file, not the same file as a source
// or as another destination, at most one "-" and only where allowed, a
// folder that exists (for a file) or can be made (for a folder). False with
// a one-line message naming the destination: "x.json: folder 'nope/' does
// not exist".
bool CheckDestinations(const std::vector<Destination>& destinations,
                       const std::vector<Source>& sources, std::string* error);

// Removes from `folder` the temporaries of AtomicFile whose process is gone
// and whose lock is free (a run that was killed); every other name is left
// alone. Returns how many were removed.
int RemoveStaleTemporaries(const std::string& folder);

// True for a name AtomicFile gives its temporaries.
bool IsGravcalTemporaryName(const std::string& name);

}  // namespace gravcal

#endif  // GRAVCAL_IO_FILES_H_

// The client half of a streamed upload (RegisterStream, RegisterProjectStream): the header message, then
// every local file in chunks of kUploadChunkBytes, then WritesDone. Shared so that both calls end the same
// way when the server refuses the header or a file becomes unreadable mid-upload.
#pragma once

#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <string>
#include <vector>

#include "commands/command_error.h"
#include "remote/local_file.h"

namespace k4reg::cli {

// Writes `header`, then the chunks of every file: make_chunk(i, piece) builds the request that carries a
// piece of files[i]; on_sent(sent_bytes, total_bytes) is called with 0 first and after every chunk.
// Returns whether the server kept the call open to the end (a failed Write means it ended the call; its
// status says why). A file that cannot be read cancels the call, finishes it and rethrows the CommandError.
template <typename Request, typename Response, typename MakeChunk, typename OnSent>
bool upload_files(grpc::ClientReaderWriter<Request, Response>& stream, grpc::ClientContext& context,
                  const Request& header, const std::vector<LocalFile>& files, MakeChunk make_chunk, OnSent on_sent) {
  bool open = stream.Write(header);
  std::uint64_t sent = 0, total = 0;
  for (const LocalFile& file : files) total += file.description.size_bytes();
  if (total > 0) on_sent(0, total);  // starts the clock of the upload rate
  try {
    for (std::size_t i = 0; i < files.size() && open; ++i) {
      FileReader reader(files[i].path, kUploadChunkBytes);
      for (const std::string* piece = &reader.next(); open && !piece->empty(); piece = &reader.next()) {
        open = stream.Write(make_chunk(i, *piece));
        if (!open) break;
        sent += piece->size();
        on_sent(sent, total);
      }
    }
  } catch (const CommandError&) {
    // Changed since it was checksummed: end the call, drain it, then report the file.
    context.TryCancel();
    for (Response ignored; stream.Read(&ignored);) {
    }
    stream.Finish();
    throw;
  }
  if (open) stream.WritesDone();
  return open;
}

}  // namespace k4reg::cli

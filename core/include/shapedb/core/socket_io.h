#pragma once
// Whole messages over a stream socket, for the worker processes that run third-party code which bad input
// can crash (TetGen, assimp): the parent waits for a reply no longer than a deadline, and a worker that
// dies is a failed call, not a signal in the parent.

#include <chrono>
#include <cstddef>

namespace shapedb::core {

using Deadline = std::chrono::steady_clock::time_point;

/// Sends all bytes on a socket; MSG_NOSIGNAL: a dead peer is an error, not a SIGPIPE.
bool sendAll(int fd, const void* data, std::size_t bytes);

/// Receives exactly `bytes`, waiting until the deadline. False on end of stream, error or timeout
/// (`timedOut` then true).
bool receiveAll(int fd, void* data, std::size_t bytes, const Deadline& deadline, bool& timedOut);

/// In a worker process just forked: its stdout and stderr go to /dev/null (whatever the third-party code
/// or a crash report writes; the descriptors are redirected, not the FILE streams, whose flushing would
/// write the parent's pending output a second time), and of the descriptors it inherited only stdio and
/// `socket` are kept, the socket as descriptor 3 (a descriptor of the parent's, another worker's socket or
/// the database file, must not outlive the parent's own copy). Returns 3.
int isolateWorker(int socket);

}  // namespace shapedb::core

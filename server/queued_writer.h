// QueuedWriter: the write side of a callback-API stream (ServerWriteReactor or
// ServerBidiReactor) as a queue: Enqueue from any thread, one StartWrite in flight at a time,
// Finish once, after the writes already queued. Never holds its mutex across a gRPC call.
// Thread-safe.
#pragma once

#include <grpcpp/grpcpp.h>

#include <deque>
#include <mutex>
#include <optional>

namespace dispatch::server {

template <class Base, class Message>
class QueuedWriter : public Base {
 public:
  // Queues `message`; dropped once the stream is finishing.
  void Enqueue(Message message) {
    std::unique_lock<std::mutex> lock(write_mu_);
    if (finishing_) return;
    queue_.push_back(std::move(message));
    if (writing_) return;
    writing_ = true;
    current_ = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    this->StartWrite(&current_);
  }

  // Finishes the stream with `status` once the queued writes are done. Idempotent.
  void RequestFinish(grpc::Status status) {
    std::unique_lock<std::mutex> lock(write_mu_);
    if (finishing_) return;
    finishing_ = true;
    if (writing_) {
      pending_ = std::move(status);
      return;
    }
    finished_ = true;
    lock.unlock();
    this->Finish(std::move(status));
  }

  void OnWriteDone(bool ok) override {
    std::unique_lock<std::mutex> lock(write_mu_);
    if (ok && !queue_.empty()) {
      current_ = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      this->StartWrite(&current_);
      return;
    }
    writing_ = false;
    if (finished_) return;
    if (!ok && !finishing_) {
      finishing_ = true;
      pending_ = grpc::Status(grpc::StatusCode::UNAVAILABLE, "stream broken");
    }
    if (!finishing_) return;
    finished_ = true;
    grpc::Status status = pending_ ? std::move(*pending_) : grpc::Status::OK;
    lock.unlock();
    this->Finish(std::move(status));
  }

 private:
  std::mutex write_mu_;  // guards everything below
  std::deque<Message> queue_;
  Message current_;  // the message being written; untouched while writing_
  bool writing_ = false;
  bool finishing_ = false;  // RequestFinish called (or a write failed)
  bool finished_ = false;   // Finish called
  std::optional<grpc::Status> pending_;
};

}  // namespace dispatch::server

#include "clients/robot_stream.h"

#include "clients/client_security.h"

namespace dispatch::clients {

RobotStream::RobotStream(v1::FleetService::Stub& stub, const v1::RobotMessage& hello,
                         std::chrono::milliseconds delay, const std::string& token)
    : delay_(delay) {
  Authorize(context_, token);
  stub.async()->Connect(&context_, this);
  // Hello goes first, undelayed: the server expects it before anything else.
  outgoing_.push_back({hello, std::chrono::steady_clock::now()});
  write_in_flight_ = true;
  writing_ = outgoing_.front().message;
  outgoing_.pop_front();
  StartWrite(&writing_);
  StartRead(&incoming_);
  StartCall();
}

RobotStream::~RobotStream() { WaitDone(); }

void RobotStream::Send(const v1::RobotMessage& message) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (closed_ || done_) return;
    outgoing_.push_back({message, std::chrono::steady_clock::now() + delay_});
  }
  MaybeStartWrite();
}

void RobotStream::DiscardPending() {
  std::lock_guard<std::mutex> lock(mu_);
  outgoing_.clear();
}

void RobotStream::Pump() { MaybeStartWrite(); }

void RobotStream::MaybeStartWrite() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (write_in_flight_ || closed_ || done_ || outgoing_.empty()) return;
    if (outgoing_.front().due > std::chrono::steady_clock::now()) return;
    writing_ = std::move(outgoing_.front().message);
    outgoing_.pop_front();
    write_in_flight_ = true;
  }
  StartWrite(&writing_);
}

std::vector<RobotStream::Received> RobotStream::TakeReceived() {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<Received> out;
  out.swap(received_);
  return out;
}

void RobotStream::Close() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (closed_ || done_) return;
    closed_ = true;
  }
  context_.TryCancel();
}

bool RobotStream::done() const {
  std::lock_guard<std::mutex> lock(mu_);
  return done_;
}

grpc::Status RobotStream::status() const {
  std::lock_guard<std::mutex> lock(mu_);
  return status_;
}

void RobotStream::WaitDone() {
  std::unique_lock<std::mutex> lock(mu_);
  done_cv_.wait(lock, [&] { return done_; });
}

void RobotStream::OnReadDone(bool ok) {
  if (!ok) return;  // the server ended its side; OnDone follows
  {
    std::lock_guard<std::mutex> lock(mu_);
    received_.push_back({incoming_, std::chrono::steady_clock::now()});
  }
  StartRead(&incoming_);
}

void RobotStream::OnWriteDone(bool ok) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    write_in_flight_ = false;
    if (!ok) {
      closed_ = true;  // the stream is broken; OnDone follows
      return;
    }
  }
  MaybeStartWrite();
}

void RobotStream::OnDone(const grpc::Status& status) {
  std::lock_guard<std::mutex> lock(mu_);
  status_ = status;
  done_ = true;
  done_cv_.notify_all();
}

}  // namespace dispatch::clients

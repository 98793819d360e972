// SPDX-License-Identifier: MIT
#pragma once

#include <CppUTest/CppUTestConfig.h>
#include <CppUTest/SimpleString.h>
#include <CppUTest/TestMemoryAllocator.h>

#include <cstddef>

namespace hrg::fakes {

// Counts operator new calls while installed (CppUTest routes the global
// operator new through the current "new" allocator). Back door: count().
class CountingNewAllocator final : public TestMemoryAllocator {
 public:
  CountingNewAllocator() : TestMemoryAllocator("counting", "new", "delete") {}
  ~CountingNewAllocator() override { uninstall(); }

  void install() {
    if (installed_) return;
    original_ = getCurrentNewAllocator();
    setCurrentNewAllocator(this);
    installed_ = true;
  }
  void uninstall() {
    if (!installed_) return;
    setCurrentNewAllocator(original_);
    installed_ = false;
  }
  char* alloc_memory(size_t size, const char* file, size_t line) override {
    ++count_;
    return original_->alloc_memory(size, file, line);
  }
  void free_memory(char* memory, size_t size, const char* file, size_t line) override {
    original_->free_memory(memory, size, file, line);
  }
  TestMemoryAllocator* actualAllocator() override { return original_->actualAllocator(); }
  std::size_t count() const { return count_; }

 private:
  TestMemoryAllocator* original_ = nullptr;
  std::size_t count_ = 0;
  bool installed_ = false;
};

}  // namespace hrg::fakes

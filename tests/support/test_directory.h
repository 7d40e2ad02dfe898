// Test helper: a fixture whose every test gets its own empty directory,
// removed afterwards, and writes its input files there.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace bouncecheck::test {

class TestDirectory : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() / (std::string("bouncecheck-") + info->test_suite_name() +
                                                         "-" + info->name() + "-" + std::to_string(::getpid()));
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }
    // `text` as the file `name` in the test's directory, byte for byte.
    std::filesystem::path write_file(const std::string& name, std::string_view text) const {
        const std::filesystem::path file = dir_ / name;
        std::ofstream(file, std::ios::binary) << text;
        return file;
    }

    std::filesystem::path dir_;
};

}  // namespace bouncecheck::test

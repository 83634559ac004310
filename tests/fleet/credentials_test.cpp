// Key files under systemd (docs/packaging.md, "colorlab-ship and colorlab-central"): the units pass each key file
// as a credential of the file's own name, and read_secret_file prefers that copy; run by hand, the configured path.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "colorlab/core/error.hpp"
#include "colorlab/fleet/config.hpp"
#include "colorlab/testing/temp_dir.hpp"

namespace fs = std::filesystem;
using colorlab::fleet::read_secret_file;

namespace {

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

// Sets CREDENTIALS_DIRECTORY for one test, as systemd does for a unit with LoadCredential=.
class CredentialsDirectory {
 public:
  explicit CredentialsDirectory(const fs::path& dir) { ::setenv("CREDENTIALS_DIRECTORY", dir.c_str(), 1); }
  ~CredentialsDirectory() { ::unsetenv("CREDENTIALS_DIRECTORY"); }
};

TEST(FleetCredentials, WithoutSystemdTheConfiguredFileIsRead) {
  colorlab::testing::TempDir dir;
  ::unsetenv("CREDENTIALS_DIRECTORY");
  write(dir / "etc/s3-secret-key", "configured-secret \r\nsecond line ignored\n");
  EXPECT_EQ(read_secret_file(dir / "etc/s3-secret-key", "S3 secret key"), "configured-secret");
}

TEST(FleetCredentials, ACredentialOfTheFilesNameIsPreferred) {
  colorlab::testing::TempDir dir;
  write(dir / "etc/s3-secret-key", "configured-secret\n");
  write(dir / "credentials/s3-secret-key", "credential-secret\n");
  CredentialsDirectory env(dir / "credentials");
  EXPECT_EQ(read_secret_file(dir / "etc/s3-secret-key", "S3 secret key"), "credential-secret");
}

TEST(FleetCredentials, AKeyFileTheUnitDoesNotPassIsReadFromItsPath) {
  colorlab::testing::TempDir dir;
  write(dir / "etc/lab-secret", "configured-secret\n");
  write(dir / "credentials/s3-secret-key", "credential-secret\n");
  CredentialsDirectory env(dir / "credentials");
  EXPECT_EQ(read_secret_file(dir / "etc/lab-secret", "S3 secret key"), "configured-secret");
}

TEST(FleetCredentials, AnEmptyCredentialIsAnErrorNamingTheFileNotTheSecret) {
  colorlab::testing::TempDir dir;
  write(dir / "etc/s3-access-key", "configured-key\n");
  write(dir / "credentials/s3-access-key", "\n");
  CredentialsDirectory env(dir / "credentials");
  try {
    read_secret_file(dir / "etc/s3-access-key", "S3 access key");
    FAIL() << "an empty credential was accepted";
  } catch (const colorlab::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir / "credentials/s3-access-key").string()), std::string::npos) << what;
    EXPECT_EQ(what.find("configured-key"), std::string::npos) << what;
  }
}

}  // namespace

// The Backends section of the C ABI (drape.h; docs/opencl.md): defaults, argument checks (a
// rejected call changes nothing), the fallback to the CPU with its reason, the device list, and a
// garment stepping on OpenCL through the ABI when a device exists (skipped otherwise).
#include "capi_test_support.h"

#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace {

drape_garment* addSmallTShirt(drape_context* ctx) {
  drape_garment_template t;
  EXPECT_EQ(drape_garment_template_init(&t), DRAPE_OK);
  t.particles = 400;
  drape_garment* g = nullptr;
  EXPECT_EQ(drape_context_add_garment_template(ctx, nullptr, &t, nullptr, &g), DRAPE_OK) << lastError();
  return g;
}

// Pushes frame i of the synthetic Kinect v2 pose (30 Hz, moved sideways by dx) and steps 1/30 s.
drape_result pushAndStep(drape_context* ctx, int i, float dx = 0.0f) {
  std::vector<drape_joint> j = poseJoints(DRAPE_LAYOUT_KINECT2, i / 30.0);
  for (drape_joint& q : j) q.position.x += dx;
  const drape_skeleton_frame f = makeFrame(DRAPE_LAYOUT_KINECT2, j, i / 30.0);
  if (drape_result r = drape_context_push_skeleton(ctx, &f)) return r;
  return drape_context_step(ctx, 1.0f / 30.0f);
}

TEST(CApiBackends, DescDefaults) {
  drape_backend_desc d;
  std::memset(&d, 0xFF, sizeof(d));
  ASSERT_OK(drape_backend_desc_init(&d));
  EXPECT_EQ(d.struct_size, sizeof(drape_backend_desc));
  EXPECT_EQ(d.backend, DRAPE_BACKEND_CPU);
  EXPECT_EQ(d.platform_index, -1);
  EXPECT_EQ(d.device_index, -1);
  EXPECT_EQ(d.prefer_gpu, 1u);
  EXPECT_EQ(d.opencl_min_particles, 2000u);
  EXPECT_EQ(d.host_cl_context, nullptr);
  EXPECT_EQ(d.host_cl_queue, nullptr);
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_backend_desc_init", drape_backend_desc_init(nullptr));
}

TEST(CApiBackends, NewContextRunsOnTheCpu) {
  ContextPtr ctx = makeContext();
  const drape_backend_info i = backendInfo(ctx.get());
  EXPECT_EQ(i.struct_size, sizeof(drape_backend_info));
  EXPECT_EQ(i.requested, DRAPE_BACKEND_CPU);
  EXPECT_EQ(i.active, DRAPE_BACKEND_CPU);
  EXPECT_EQ(i.opencl_garments, 0u);
  EXPECT_STREQ(i.device_name, "");
  EXPECT_STREQ(i.fallback_reason, "");
}

TEST(CApiBackends, BadArgumentsAreRejectedAndChangeNothing) {
  ContextPtr ctx = makeContext();
  drape_backend_desc d;
  ASSERT_OK(drape_backend_desc_init(&d));
  const char* fn = "drape_context_set_backend";
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_context_set_backend(nullptr, &d));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, fn, drape_context_set_backend(ctx.get(), nullptr));
  EXPECT_FAILS(DRAPE_ERROR_INVALID_HANDLE, fn,
               drape_context_set_backend(reinterpret_cast<drape_context*>(uintptr_t{0x1234}), &d));
  auto bad = [&](drape_result code, const std::function<void(drape_backend_desc&)>& change) {
    drape_backend_desc b = d;
    b.backend = DRAPE_BACKEND_OPENCL;  // a valid request spoilt by one field
    change(b);
    EXPECT_FAILS(code, fn, drape_context_set_backend(ctx.get(), &b));
    EXPECT_EQ(backendInfo(ctx.get()).requested, DRAPE_BACKEND_CPU);  // nothing changed
  };
  bad(DRAPE_ERROR_INVALID_ARGUMENT, [](drape_backend_desc& b) { b.struct_size = 8; });
  bad(DRAPE_ERROR_OUT_OF_RANGE, [](drape_backend_desc& b) { b.backend = 3; });
  bad(DRAPE_ERROR_OUT_OF_RANGE, [](drape_backend_desc& b) { b.backend = -1; });
  bad(DRAPE_ERROR_OUT_OF_RANGE, [](drape_backend_desc& b) { b.platform_index = -2; });
  bad(DRAPE_ERROR_OUT_OF_RANGE, [](drape_backend_desc& b) { b.device_index = 256; });
  bad(DRAPE_ERROR_OUT_OF_RANGE, [](drape_backend_desc& b) { b.prefer_gpu = 2; });
  bad(DRAPE_ERROR_OUT_OF_RANGE, [](drape_backend_desc& b) { b.opencl_min_particles = 100000001u; });
  bad(DRAPE_ERROR_INVALID_ARGUMENT, [](drape_backend_desc& b) { b.host_cl_context = &b; });
  bad(DRAPE_ERROR_INVALID_ARGUMENT, [](drape_backend_desc& b) { b.host_cl_queue = &b; });

  drape_backend_info i;
  i.struct_size = 4;
  const char* gi = "drape_context_get_backend_info";
  EXPECT_FAILS(DRAPE_ERROR_INVALID_ARGUMENT, gi, drape_context_get_backend_info(ctx.get(), &i));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, gi, drape_context_get_backend_info(ctx.get(), nullptr));
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, gi, drape_context_get_backend_info(nullptr, &i));

  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_opencl_device_count", drape_opencl_device_count(nullptr));
  drape_opencl_device dev;
  dev.struct_size = sizeof(dev);
  EXPECT_FAILS(DRAPE_ERROR_NULL_ARGUMENT, "drape_opencl_device_get", drape_opencl_device_get(0, nullptr));
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_opencl_device_get", drape_opencl_device_get(100000, &dev));
  dev.struct_size = 3;
  EXPECT_FAILS(DRAPE_ERROR_INVALID_ARGUMENT, "drape_opencl_device_get", drape_opencl_device_get(0, &dev));
}

TEST(CApiBackends, ImpossibleDeviceFallsBackWithTheReason) {
  ContextPtr ctx = makeContext();
  drape_garment* g = addSmallTShirt(ctx.get());
  ASSERT_NE(g, nullptr);
  drape_backend_desc d;
  ASSERT_OK(drape_backend_desc_init(&d));
  d.backend = DRAPE_BACKEND_OPENCL;
  d.platform_index = 200;  // no machine has 201 OpenCL platforms
  ASSERT_OK(drape_context_set_backend(ctx.get(), &d));
  const drape_backend_info i = backendInfo(ctx.get());
  EXPECT_EQ(i.requested, DRAPE_BACKEND_OPENCL);
  EXPECT_EQ(i.active, DRAPE_BACKEND_CPU);
  EXPECT_EQ(i.cpu_garments, 1u);
  EXPECT_STRNE(i.fallback_reason, "");
  EXPECT_STREQ(i.device_name, "");
  // The garment still steps (on the CPU).
  for (int f = 0; f < 3; ++f) ASSERT_OK(pushAndStep(ctx.get(), f));
  drape_garment_stats st;
  st.struct_size = sizeof(st);
  ASSERT_OK(drape_garment_get_stats(g, &st));
  EXPECT_GT(st.substeps, 0u);
}

TEST(CApiBackends, DeviceListIsConsistent) {
  uint32_t n = 12345;
  ASSERT_OK(drape_opencl_device_count(&n));
  EXPECT_LT(n, 1000u);
  for (uint32_t k = 0; k < n; ++k) {
    drape_opencl_device d;
    d.struct_size = sizeof(d);
    ASSERT_OK(drape_opencl_device_get(k, &d));
    EXPECT_EQ(d.struct_size, sizeof(d));
    EXPECT_GE(d.platform_index, 0);
    EXPECT_GE(d.device_index, 0);
    EXPECT_NE(d.device_name[0], '\0');
    EXPECT_GT(d.global_mem_bytes, 0u);
  }
  drape_opencl_device d;
  d.struct_size = sizeof(d);
  EXPECT_FAILS(DRAPE_ERROR_OUT_OF_RANGE, "drape_opencl_device_get", drape_opencl_device_get(n, &d));
}

TEST(CApiBackends, GarmentStepsOnOpenClWhenADeviceExists) {
  uint32_t n = 0;
  ASSERT_OK(drape_opencl_device_count(&n));
  if (n == 0) GTEST_SKIP() << "no OpenCL device on this machine";
  ContextPtr ctx = makeContext();
  drape_garment* g = addSmallTShirt(ctx.get());
  ASSERT_NE(g, nullptr);
  drape_backend_desc d;
  ASSERT_OK(drape_backend_desc_init(&d));
  d.backend = DRAPE_BACKEND_OPENCL;
  ASSERT_OK(drape_context_set_backend(ctx.get(), &d));
  const drape_backend_info i = backendInfo(ctx.get());
  if (i.active != DRAPE_BACKEND_OPENCL) GTEST_SKIP() << "OpenCL device unusable: " << i.fallback_reason;
  EXPECT_EQ(i.opencl_garments, 1u);
  EXPECT_NE(i.device_name[0], '\0');
  EXPECT_STREQ(i.fallback_reason, "");
  for (int f = 0; f < 5; ++f) ASSERT_OK(pushAndStep(ctx.get(), f, 0.01f * static_cast<float>(f)));
  const float* x = nullptr;
  uint32_t count = 0;
  ASSERT_OK(drape_garment_view_positions(g, &x, &count));
  ASSERT_GT(count, 0u);
  for (uint32_t k = 0; k < 4 * count; ++k) ASSERT_TRUE(std::isfinite(x[k]));
  drape_garment_stats st;
  st.struct_size = sizeof(st);
  ASSERT_OK(drape_garment_get_stats(g, &st));
  EXPECT_GT(st.contacts, 0u);
  // A second garment added later lands on the device too; AUTO with a high threshold moves both back.
  drape_garment* g2 = addSmallTShirt(ctx.get());
  ASSERT_NE(g2, nullptr);
  EXPECT_EQ(backendInfo(ctx.get()).opencl_garments, 2u);
  d.backend = DRAPE_BACKEND_AUTO;
  d.opencl_min_particles = 100000;
  ASSERT_OK(drape_context_set_backend(ctx.get(), &d));
  EXPECT_EQ(backendInfo(ctx.get()).opencl_garments, 0u);
  EXPECT_EQ(backendInfo(ctx.get()).active, DRAPE_BACKEND_CPU);
  ASSERT_OK(pushAndStep(ctx.get(), 6));
}

}  // namespace

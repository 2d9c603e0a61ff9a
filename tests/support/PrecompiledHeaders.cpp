// The translation unit that compiles tests/CMakeLists.txt's precompiled headers (tickfx_test_pch),
// which every test executable of a unity build reuses. It has no code of its own.

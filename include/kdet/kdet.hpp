#pragma once
/// @file kdet.hpp
/// @brief Everything of kdet's public API.

#include <kdet/config.hpp>
#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/locate.hpp>
#include <kdet/mesh.hpp>
#include <kdet/option_table.hpp>
#include <kdet/options.hpp>
#include <kdet/results.hpp>

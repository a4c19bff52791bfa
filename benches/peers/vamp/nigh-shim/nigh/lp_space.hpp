#pragma once
#include "nigh_forward.hpp"

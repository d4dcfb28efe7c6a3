//! The integration tests of `eenf-sim`, one test binary (each file was its own binary,
//! linking the whole workspace again).

mod extract_truth;
mod physics;
mod unit_lamp;
mod unit_mains;
mod unit_scene;
mod unit_sensor_pixel;

pub mod cubature;

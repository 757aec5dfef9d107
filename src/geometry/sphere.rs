use super::*;
#[derive(Debug, Clone)]
pub struct Sphere;

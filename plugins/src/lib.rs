pub fn x(){}
pub mod record;
